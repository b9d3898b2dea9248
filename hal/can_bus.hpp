#pragma once
/// Classic CAN, 11-bit identifiers, non-blocking in both directions.
#include <array>
#include <cstdint>

namespace imd::hal {

struct CanFrame {
  uint16_t id = 0;     ///< 11-bit identifier
  uint8_t length = 0;  ///< 0..8
  std::array<uint8_t, 8> data{};
};

class CanBus {
 protected:
  // Never deleted through the interface (nothing is allocated): no virtual destructor, so
  // no deleting destructor and no operator delete in the vtables of the firmware.
  ~CanBus() = default;

 public:
  /// Queues a frame; false if the transmit queue is full (the frame is dropped and counted by
  /// the caller). Never blocks.
  virtual bool try_send(const CanFrame& frame) noexcept = 0;
  /// Takes the oldest received frame; false if none. Never blocks.
  virtual bool try_receive(CanFrame& frame) noexcept = 0;
  /// The controller is bus-off (it has stopped sending after too many errors). Tick context.
  virtual bool bus_off() const noexcept { return false; }
};

}  // namespace imd::hal
