#pragma once
/// Models of the board's sensors and of the inverter's average output: quantized phase-current
/// and DC-bus ADC with offset and Gaussian noise, a quantized position-only encoder, and the
/// average phase voltages of a two-level inverter.
#include <array>
#include <cstdint>

#include "control/frames.hpp"
#include "hal/current_adc.hpp"
#include "hal/pwm.hpp"
#include "hal_sim/gaussian_noise.hpp"

namespace imd::sim {

struct AdcModelConfig {
  int bits = 12;
  double full_scale_A = 10.0;                     ///< codes span -full_scale_A .. +full_scale_A
  double noise_A = 0.0;                           ///< standard deviation of the phase-current noise
  std::array<double, 3> offset_A{0.0, 0.0, 0.0};  ///< offset of each phase channel
  double bus_full_scale_V = 500.0;                ///< codes span 0 .. bus_full_scale_V
  double bus_noise_V = 0.0;
};

/// Converts true phase currents and bus voltage to ADC codes. Deterministic for a given seed.
class AdcModel {
 public:
  AdcModel(const AdcModelConfig& config, uint64_t seed);
  hal::AdcScale scale() const noexcept { return scale_; }
  hal::AdcSample convert(const std::array<double, 3>& i_abc_A, double v_bus_V) noexcept;

 private:
  uint16_t to_code(double value, double per_code, int mid) const noexcept;

  AdcModelConfig config_;
  hal::AdcScale scale_;
  GaussianNoise unit_normal_;
};

/// Encoder count of a mechanical angle: floor(theta cpr / 2 pi), wrapped to 32 bits like a
/// hardware counter.
uint32_t encoder_count(double theta_mech_rad, uint32_t counts_per_rev) noexcept;

/// Average stator voltage (alpha-beta) of a two-level inverter with these duties: the pole
/// voltages duty * v_bus less their common mode, which an isolated star point does not see.
control::Vec2<double> inverter_output_V(const hal::PhaseDuties& duty, double v_bus_V) noexcept;

}  // namespace imd::sim
