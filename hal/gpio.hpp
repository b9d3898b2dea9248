#pragma once
/// Digital lines by board-specific index: fault LED, enable input, and the like.
#include <cstdint>

namespace imd::hal {

class Gpio {
 protected:
  // Never deleted through the interface (nothing is allocated): no virtual destructor, so
  // no deleting destructor and no operator delete in the vtables of the firmware.
  ~Gpio() = default;

 public:
  /// Drives an output line. Tick context.
  virtual void write(uint8_t line, bool level) noexcept = 0;
  /// Reads a line. Tick context.
  virtual bool read(uint8_t line) const noexcept = 0;
};

}  // namespace imd::hal
