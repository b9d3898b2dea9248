#pragma once
/// What the sense stage hands on: one tick's phase currents, DC bus and encoder reading, in SI
/// units, in the stationary frame. Plain data, made once per tick.
#include <array>
#include <cstdint>

#include "control/frames.hpp"

namespace imd::firmware {

/// The ADC offset calibration, while the drive is calibrating.
enum class Calibration : uint8_t {
  none,          ///< not calibrating this tick
  running,       ///< still averaging the codes with the PWM off
  done,          ///< the offsets are known (and within their limit)
  offset_fault,  ///< a phase's offset is beyond its limit (offset_fault_phase)
};

template <typename T>
struct Measurement {
  /// Currents scaled with known offsets and the encoder read: false while calibrating, and
  /// after a fault that came before the offsets were known.
  bool valid = false;
  Calibration calibration = Calibration::none;
  uint8_t offset_fault_phase = 0;

  std::array<uint16_t, 3> phase_code{};  ///< raw, for the stuck-converter check
  T i_abc_A[3] = {T(0), T(0), T(0)};     ///< phase currents a, b, c
  control::Vec2<T> i_alphabeta_A = control::Vec2<T>::Zero();
  T i_peak_A = T(0);           ///< largest |phase current|
  bool adc_saturated = false;  ///< a phase code on a rail: beyond what the ADC measures
  T v_bus_V = T(0);

  int32_t encoder_delta_counts = 0;  ///< counts over the last period
  T theta_encoder_rad = T(0);        ///< measured mechanical angle, [0, 2 pi)
  bool encoder_first = false;        ///< the first reading: it sets the observer's angle
};

}  // namespace imd::firmware
