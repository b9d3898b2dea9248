#include "firmware/stages/sense.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>

#include "control/svpwm.hpp"
#include "hal/u64_to_real.hpp"

namespace imd::firmware {

template <typename T>
BoardSensing<T>::BoardSensing(hal::CurrentAdc& adc, hal::Encoder& encoder,
                              const SensingConfig& config) noexcept
    : adc_(adc),
      encoder_(encoder),
      calibration_ticks_(config.adc_calibration_ticks),
      offset_limit_A_(T(config.adc_offset_limit_A)),
      A_per_code_(T(adc.scale().phase_A_per_code)),
      V_per_code_(T(adc.scale().bus_V_per_code)),
      mid_code_(T(adc.scale().phase_mid_code)),
      max_code_(adc.scale().max_code),
      counts_per_rev_(static_cast<int32_t>(encoder.counts_per_rev())),
      rad_per_count_(T(2) * std::numbers::pi_v<T> / T(counts_per_rev_)) {
  if (calibration_ticks_ <= 0) {
    for (T& offset : offset_code_) offset = mid_code_;
    calibrated_ = true;
  }
}

template <typename T>
Measurement<T> BoardSensing<T>::measure(bool calibrating) noexcept {
  Measurement<T> m;
  const hal::AdcSample sample = adc_.sample();
  m.phase_code = sample.phase_code;
  m.v_bus_V = T(sample.bus_code) * V_per_code_;
  if (calibrating) {
    m.calibration = calibrate(sample, m);
    return m;
  }
  was_calibrating_ = false;
  if (!calibrated_) return m;  // a fault before the offsets were known: nothing to measure
  read_encoder(m);
  for (int phase = 0; phase < 3; ++phase) {
    m.i_abc_A[phase] = (T(sample.phase_code[phase]) - offset_code_[phase]) * A_per_code_;
    m.i_peak_A = std::max(m.i_peak_A, std::abs(m.i_abc_A[phase]));
    m.adc_saturated =
        m.adc_saturated || sample.phase_code[phase] == 0 || sample.phase_code[phase] >= max_code_;
  }
  m.i_alphabeta_A =
      control::clarke(control::PhaseValues<T>{m.i_abc_A[0], m.i_abc_A[1], m.i_abc_A[2]});
  m.valid = true;
  return m;
}

template <typename T>
Calibration BoardSensing<T>::calibrate(const hal::AdcSample& sample, Measurement<T>& m) noexcept {
  if (!was_calibrating_) {  // a new calibration (at power-up, or after a fault cleared)
    calibration_count_ = 0;
    for (int64_t& sum : calibration_sum_) sum = 0;
    was_calibrating_ = true;
  }
  for (int phase = 0; phase < 3; ++phase) calibration_sum_[phase] += sample.phase_code[phase];
  if (++calibration_count_ < calibration_ticks_) return Calibration::running;
  was_calibrating_ = false;
  for (int phase = 0; phase < 3; ++phase) {
    // Not a 64-bit conversion (a library call on the MCU); the sum of codes is not negative.
    offset_code_[phase] =
        hal::u64_to_real<T>(static_cast<uint64_t>(calibration_sum_[phase])) / T(calibration_count_);
    const T offset_A = (offset_code_[phase] - mid_code_) * A_per_code_;
    if (std::abs(offset_A) > offset_limit_A_) {
      m.offset_fault_phase = uint8_t(phase);
      return Calibration::offset_fault;
    }
  }
  calibrated_ = true;
  return Calibration::done;
}

template <typename T>
inline void BoardSensing<T>::read_encoder(Measurement<T>& m) noexcept {
  // Unwrap the free-running counter by differences, keep one revolution. 32-bit: the MCU
  // divides those in hardware (cpr <= 2^30, |delta| < 2^31 - 2^30).
  const uint32_t count = encoder_.count();
  const int32_t cpr = counts_per_rev_;
  m.encoder_first = !encoder_started_;
  if (!encoder_started_) last_encoder_count_ = count;
  encoder_started_ = true;
  m.encoder_delta_counts = static_cast<int32_t>(count - last_encoder_count_);
  last_encoder_count_ = count;
  // The position is in [0, cpr) and the step's remainder in (-cpr, cpr): one correction by a
  // revolution brings the sum back into [0, cpr), without two more divisions.
  encoder_position_ += m.encoder_delta_counts % cpr;
  if (encoder_position_ < 0) {
    encoder_position_ += cpr;
  } else if (encoder_position_ >= cpr) {
    encoder_position_ -= cpr;
  }
  m.theta_encoder_rad = T(encoder_position_) * rad_per_count_;
}

template class BoardSensing<float>;
template class BoardSensing<double>;

}  // namespace imd::firmware
