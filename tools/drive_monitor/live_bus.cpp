#include "tools/drive_monitor/live_bus.hpp"

#include <poll.h>

#include <cerrno>
#include <cstring>

namespace imd::monitor::cli {

CLI::Option* add_bus_options(CLI::App& command, BusChoice& choice) {
  CLI::Option* can =
      command.add_option("--can", choice.can, "CAN interface (SocketCAN), e.g. can0");
  command
      .add_option("--socketcand", choice.socketcand,
                  "socketcand server instead of an interface: PORT (on 127.0.0.1), HOST:PORT or "
                  "[V6]:PORT, e.g. 127.0.0.1:29536 "
                  "(drive_hil --can socketcand:29536)")
      ->excludes(can);
  return can;
}

std::unique_ptr<LiveBus> LiveBus::open(const BusChoice& choice, std::string& error) {
  std::unique_ptr<LiveBus> bus(new LiveBus());
  if (!choice.socketcand.empty()) {
    std::string host;
    uint16_t port = 0;
    if (!hal::parse_socketcand_address(choice.socketcand, host, port, error)) return nullptr;
    bus->socketcand_ = hal::SocketcandClient::open(host, port, error);
    if (!bus->socketcand_) return nullptr;
    bus->name_ = "socketcand " + bus->socketcand_->address();
  } else {
    bus->socketcan_ = hal::SocketCanBus::open(choice.can, error);
    if (!bus->socketcan_) return nullptr;
    bus->name_ = choice.can;
  }
  return bus;
}

bool LiveBus::try_send(const hal::CanFrame& frame) noexcept {
  return socketcan_ ? socketcan_->try_send(frame) : socketcand_->try_send(frame);
}

bool LiveBus::try_receive(hal::CanFrame& frame) noexcept {
  return socketcan_ ? socketcan_->try_receive(frame) : socketcand_->try_receive(frame);
}

short LiveBus::poll_events() const noexcept {
  return socketcand_ ? socketcand_->poll_events() : static_cast<short>(POLLIN);
}

int LiveBus::native_handle() const noexcept {
  return socketcan_ ? socketcan_->native_handle() : socketcand_->native_handle();
}

std::optional<std::string> LiveBus::lost() const {
  if (socketcand_) {
    if (socketcand_->lost().empty()) return std::nullopt;
    return name_ + ": " + socketcand_->lost();
  }
  const int error = socketcan_->last_errno();
  if (error != ENODEV && error != ENETDOWN) return std::nullopt;
  return name_ + ": " + std::strerror(error);
}

std::optional<BusInfo> LiveBus::info() const {
  if (!socketcan_) return std::nullopt;
  const hal::CanErrorState& e = socketcan_->errors();
  return BusInfo{e.error_frames, e.bus_off_events, e.bus_off,
                 hal::describe_error_class(e.last_error_class), socketcan_->unsupported_frames()};
}

uint64_t LiveBus::unsupported_frames() const noexcept {
  return socketcan_ ? socketcan_->unsupported_frames() : socketcand_->skipped_messages();
}

}  // namespace imd::monitor::cli
