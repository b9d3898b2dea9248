#include "hal_sim/sensor_models.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>

#include "control/svpwm.hpp"

namespace imd::sim {

AdcModel::AdcModel(const AdcModelConfig& config, uint64_t seed)
    : config_(config), unit_normal_(seed) {
  const int codes = 1 << config.bits;
  scale_.phase_A_per_code = static_cast<float>(2.0 * config.full_scale_A / codes);
  scale_.phase_mid_code = static_cast<uint16_t>(codes / 2);
  scale_.bus_V_per_code = static_cast<float>(config.bus_full_scale_V / codes);
  scale_.max_code = static_cast<uint16_t>(codes - 1);
}

namespace {

/// std::round (halves away from zero) without the library call, for |x| < 2^52: the
/// truncation is exact there, and so is x minus it. The step away from zero is added as 0 or
/// +-1, not chosen by a branch: with sensor noise its direction is a coin toss, which a branch
/// predictor misses every other sample.
double round_half_away(double x) noexcept {
  if (!(std::fabs(x) < 0x1p52)) return std::round(x);
  const auto whole = static_cast<double>(static_cast<int64_t>(x));
  return whole + std::copysign(static_cast<double>(std::fabs(x - whole) >= 0.5), x);
}

}  // namespace

uint16_t AdcModel::to_code(double value, double per_code, int mid) const noexcept {
  const double code = round_half_away(value / per_code) + mid;
  return static_cast<uint16_t>(std::clamp(code, 0.0, static_cast<double>(scale_.max_code)));
}

hal::AdcSample AdcModel::convert(const std::array<double, 3>& i_abc_A, double v_bus_V) noexcept {
  hal::AdcSample sample;
  const double a_per_code = 2.0 * config_.full_scale_A / (1 << config_.bits);
  for (int phase = 0; phase < 3; ++phase) {
    const double measured =
        i_abc_A[phase] + config_.offset_A[phase] + config_.noise_A * unit_normal_();
    sample.phase_code[phase] = to_code(measured, a_per_code, scale_.phase_mid_code);
  }
  const double bus = v_bus_V + config_.bus_noise_V * unit_normal_();
  sample.bus_code = to_code(bus, config_.bus_full_scale_V / (1 << config_.bits), 0);
  return sample;
}

uint32_t encoder_count(double theta_mech_rad, uint32_t counts_per_rev) noexcept {
  const double counts = std::floor(theta_mech_rad * counts_per_rev / (2.0 * std::numbers::pi));
  return static_cast<uint32_t>(static_cast<int64_t>(counts));
}

control::Vec2<double> inverter_output_V(const hal::PhaseDuties& duty, double v_bus_V) noexcept {
  return control::clarke(
      control::PhaseValues<double>{duty[0] * v_bus_V, duty[1] * v_bus_V, duty[2] * v_bus_V});
}

}  // namespace imd::sim
