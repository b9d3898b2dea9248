#pragma once
/// The bus a live subcommand talks on, opened in one place: a SocketCAN interface (--can IFACE)
/// or a socketcand server such as `drive_hil --can socketcand:PORT` (--socketcand HOST:PORT).
#include <CLI/CLI.hpp>

#include <memory>
#include <optional>
#include <string>

#include "hal/can_bus.hpp"
#include "hal/linux/socketcan_bus.hpp"
#include "hal/linux/socketcand_client.hpp"
#include "tools/drive_monitor/status_table.hpp"

namespace imd::monitor::cli {

/// --can and --socketcand as given (one of them, or neither where --log stands instead).
struct BusChoice {
  std::string can;
  std::string socketcand;
  bool given() const { return !can.empty() || !socketcand.empty(); }
};

/// Adds --can IFACE and --socketcand HOST:PORT, each excluding the other; the first is returned
/// (for further excludes).
CLI::Option* add_bus_options(CLI::App& command, BusChoice& choice);

class LiveBus final : public hal::CanBus {
 public:
  /// Opens the chosen bus; nullptr and `error` (naming the interface or the server) on failure.
  static std::unique_ptr<LiveBus> open(const BusChoice& choice, std::string& error);

  bool try_send(const hal::CanFrame& frame) noexcept override;
  bool try_receive(hal::CanFrame& frame) noexcept override;

  /// The descriptor to wait on for received frames.
  int native_handle() const noexcept;
  /// The events to poll native_handle() for (POLLOUT too while a socketcand frame is unsent).
  short poll_events() const noexcept;
  /// Why the bus is gone (interface down or removed, server closed the connection); nullopt
  /// while it works. Waiting for it to come back is not this tool's job.
  std::optional<std::string> lost() const;
  /// SocketCAN's error counters for the table; nullopt over socketcand (no error frames on TCP).
  std::optional<BusInfo> info() const;
  /// Frames skipped by the bus itself: unsupported SocketCAN frames, or socketcand messages
  /// that were not 11-bit frames.
  uint64_t unsupported_frames() const noexcept;
  /// "can0", or "socketcand 127.0.0.1:29536": for messages and the table.
  const std::string& name() const noexcept { return name_; }

 private:
  LiveBus() = default;
  std::unique_ptr<hal::SocketCanBus> socketcan_;
  std::unique_ptr<hal::SocketcandClient> socketcand_;
  std::string name_;
};

}  // namespace imd::monitor::cli
