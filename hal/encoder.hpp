#pragma once
/// Incremental quadrature encoder. The counter is free-running and wraps; the application
/// unwraps it by differences.
#include <cstdint>

namespace imd::hal {

class Encoder {
 protected:
  // Never deleted through the interface (nothing is allocated): no virtual destructor, so
  // no deleting destructor and no operator delete in the vtables of the firmware.
  ~Encoder() = default;

 public:
  /// Counter value latched at the start of the tick. Tick context.
  virtual uint32_t count() const noexcept = 0;
  /// Counts per mechanical revolution (four times the line count for quadrature).
  virtual uint32_t counts_per_rev() const noexcept = 0;
};

}  // namespace imd::hal
