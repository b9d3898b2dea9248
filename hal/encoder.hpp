#pragma once
/// Incremental quadrature encoder. The counter is free-running and wraps; the application
/// unwraps it by differences.
#include <cstdint>

namespace imd::hal {

class Encoder {
 public:
  virtual ~Encoder() = default;
  /// Counter value latched at the start of the tick. Tick context.
  virtual uint32_t count() const noexcept = 0;
  /// Counts per mechanical revolution (four times the line count for quadrature).
  virtual uint32_t counts_per_rev() const noexcept = 0;
};

}  // namespace imd::hal
