#pragma once
/// hal::CanBus over a Linux SocketCAN raw socket (PF_CAN, SOCK_RAW, CAN_RAW), for host tools.
/// Non-blocking in both directions. Classic 11-bit data frames only: extended, remote and CAN FD
/// frames received are dropped and counted. Error frames are enabled (CAN_RAW_ERR_FILTER),
/// counted, and a bus-off (CAN_ERR_BUSOFF) is reported by bus_off() until the controller
/// restarts (CAN_ERR_RESTARTED).
#include <linux/can.h>

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "hal/can_bus.hpp"

namespace imd::hal {

/// Receive filter: a frame passes when (frame.id & mask) == (id & mask), 11-bit values. With
/// no filter every standard data frame passes.
struct CanIdFilter {
  uint16_t id = 0;
  uint16_t mask = 0;
};

/// struct can_frame -> CanFrame. False (and `out` unchanged) for extended, remote and error
/// frames and for a length above 8.
bool from_socketcan(const can_frame& in, CanFrame& out) noexcept;

/// CanFrame -> struct can_frame. False for an identifier above 0x7FF or a length above 8.
bool to_socketcan(const CanFrame& in, can_frame& out) noexcept;

/// What the error frames received so far said.
struct CanErrorState {
  uint32_t error_frames = 0;      ///< all error frames
  uint32_t last_error_class = 0;  ///< can_id & CAN_ERR_MASK of the last one (CAN_ERR_* bits)
  uint32_t bus_off_events = 0;    ///< error frames with CAN_ERR_BUSOFF
  bool bus_off = false;           ///< set by CAN_ERR_BUSOFF, cleared by CAN_ERR_RESTARTED
};

/// Accounts for one error frame (`frame.can_id` has CAN_ERR_FLAG); other frames are ignored.
void account_error_frame(const can_frame& frame, CanErrorState& state) noexcept;

/// The CAN_ERR_* class bits as words, e.g. "bus-off, no-ack"; "none" for 0.
std::string describe_error_class(uint32_t error_class);

class SocketCanBus final : public CanBus {
 public:
  /// Opens a raw CAN socket bound to `iface`. On failure returns nullptr and sets `error` to a
  /// message that names the interface, e.g. "vcan9: no such CAN interface" or "can0:
  /// socket(PF_CAN): Address family not supported by protocol (no CAN support in this kernel)".
  static std::unique_ptr<SocketCanBus> open(const std::string& iface, std::string& error,
                                            const std::vector<CanIdFilter>& filters = {});

  ~SocketCanBus();
  SocketCanBus(const SocketCanBus&) = delete;
  SocketCanBus& operator=(const SocketCanBus&) = delete;

  /// False if the frame is invalid or the kernel's queue is full or the interface is down.
  bool try_send(const CanFrame& frame) noexcept override;
  /// The oldest received standard data frame; error frames and unsupported frames on the way
  /// are accounted for and skipped. False if none is waiting.
  bool try_receive(CanFrame& frame) noexcept override;

  /// The controller reported bus-off and has not restarted since.
  bool bus_off() const noexcept override { return errors_.bus_off; }
  const CanErrorState& errors() const noexcept { return errors_; }
  /// Received frames dropped because they are not classic 11-bit data frames.
  uint32_t unsupported_frames() const noexcept { return unsupported_frames_; }
  /// Frames try_send could not queue.
  uint32_t send_failures() const noexcept { return send_failures_; }
  /// errno of the last failed read or write other than "would block" (0: none).
  int last_errno() const noexcept { return last_errno_; }
  /// The socket, for poll(); stays owned by this object.
  int native_handle() const noexcept { return fd_; }
  const std::string& iface() const noexcept { return iface_; }

 private:
  SocketCanBus(int fd, std::string iface) noexcept : fd_(fd), iface_(std::move(iface)) {}

  int fd_;
  std::string iface_;
  CanErrorState errors_;
  uint32_t unsupported_frames_ = 0;
  uint32_t send_failures_ = 0;
  int last_errno_ = 0;
};

}  // namespace imd::hal
