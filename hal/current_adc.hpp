#pragma once
/// Phase-current and DC-bus ADC, sampled synchronously with the PWM carrier. Raw codes; the
/// application owns offset calibration and scaling, so a wrong offset can be detected.
#include <array>
#include <cstdint>

namespace imd::hal {

struct AdcSample {
  std::array<uint16_t, 3> phase_code{};  ///< phases a, b, c
  uint16_t bus_code = 0;                 ///< DC-bus voltage
};

/// Scaling of the converter: current = (code - mid_code) * A_per_code, bus = code * V_per_code.
struct AdcScale {
  float phase_A_per_code = 0.0f;
  uint16_t phase_mid_code = 0;  ///< nominal code at zero current
  float bus_V_per_code = 0.0f;
  uint16_t max_code = 0;  ///< full-scale code, 2^bits - 1
};

class CurrentAdc {
 protected:
  // Never deleted through the interface (nothing is allocated): no virtual destructor, so
  // no deleting destructor and no operator delete in the vtables of the firmware.
  ~CurrentAdc() = default;

 public:
  /// The conversion triggered at the start of this tick. Tick context.
  virtual AdcSample sample() const noexcept = 0;
  virtual AdcScale scale() const noexcept = 0;
};

}  // namespace imd::hal
