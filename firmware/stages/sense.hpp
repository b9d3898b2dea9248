#pragma once
/// The sense stage: ADC codes and the encoder counter -> a Measurement. The board's sensors
/// (BoardSensing) are the production source; a simulation may substitute its ideal sensors
/// (hal_sim/drive/ideal_sensors.hpp) through the same interface. Tick context.
#include <cstdint>

#include "control/real.hpp"
#include "firmware/stages/measurement.hpp"
#include "hal/current_adc.hpp"
#include "hal/encoder.hpp"

namespace imd::firmware {

template <typename T>
class Sensing {
 protected:
  // Never deleted through the interface (nothing is allocated): no virtual destructor, so
  // no deleting destructor and no operator delete in the vtables of the firmware.
  ~Sensing() = default;

 public:
  /// This tick's measurement. While `calibrating`, the ADC offsets are measured instead (the
  /// PWM is off); a calibration that ends starts again at the next call with `calibrating`.
  virtual Measurement<T> measure(bool calibrating) noexcept = 0;
};

struct SensingConfig {
  int adc_calibration_ticks = 256;  ///< 0: nominal offsets, no calibration
  Real adc_offset_limit_A = 0.5;    ///< a larger measured offset is a fault
};

/// The board's ADC and encoder: offset calibration and scaling, encoder unwrapping.
template <typename T>
class BoardSensing final : public Sensing<T> {
 public:
  BoardSensing(hal::CurrentAdc& adc, hal::Encoder& encoder, const SensingConfig& config) noexcept;

  Measurement<T> measure(bool calibrating) noexcept override;
  /// The offsets are known (after a calibration, or nominal when none is configured).
  bool calibrated() const noexcept { return calibrated_; }

 private:
  Calibration calibrate(const hal::AdcSample& sample, Measurement<T>& m) noexcept;
  [[gnu::always_inline]] inline void read_encoder(Measurement<T>& m) noexcept;  // one caller

  hal::CurrentAdc& adc_;
  hal::Encoder& encoder_;
  int calibration_ticks_;
  T offset_limit_A_;
  // The converter's fixed scaling, in T (read once).
  T A_per_code_, V_per_code_, mid_code_;
  uint16_t max_code_;
  int32_t counts_per_rev_;
  T rad_per_count_;  ///< 2 pi / counts_per_rev_: the angle multiplies, never divides

  bool calibrated_ = false;
  bool was_calibrating_ = false;
  int calibration_count_ = 0;
  int64_t calibration_sum_[3] = {0, 0, 0};
  T offset_code_[3] = {T(0), T(0), T(0)};
  bool encoder_started_ = false;
  uint32_t last_encoder_count_ = 0;
  int32_t encoder_position_ = 0;  ///< counts within one revolution, [0, cpr)
};

}  // namespace imd::firmware
