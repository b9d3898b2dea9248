// The drive's service loop (Drive::service): what must not run in the tick. It rebuilds the
// motor model after a parameter write or a commissioning, and on the tracked rotor resistance
// (docs/robustness.md), and plans and adopts the commissioning; and the program's shut-down
// after the last tick. Main loop, never the tick.
#include <cmath>

#include "firmware/drive.hpp"
#include "firmware/identification/commissioned_motor.hpp"

namespace imd::firmware {

template <typename T>
void Drive<T>::service() noexcept {
  switch (bank_.stage()) {
    case ParameterBank::Stage::access:
      if constexpr (kCommissioningInImage) {
        if (bank_.access().op == protocol::ParameterOp::identify) {
          plan_commissioning();
          return;
        }
        if (bank_.access().op == protocol::ParameterOp::identified) {
          adopt_commissioning();
          return;
        }
      }
      bank_.serve(hw_.store);  // without the commissioning, the supervisor sends no identify
      return;
    case ParameterBank::Stage::apply:
      // The tick let go of the model before it asked: it is the service loop's to rebuild.
      rebuild(bank_.staged());
      bank_.applied();
      return;
    case ParameterBank::Stage::free:
      retune();
      return;
    case ParameterBank::Stage::answered:  // a staged record may be on its way: no retune now
      return;
  }
}

template <typename T>
void Drive<T>::rebuild(const control::MotorParameters& motor) noexcept {
  // The tick has let go of every model (it swaps only while attached). The last estimate was
  // the old model's: forgotten, so that no retune undoes the new record's Rr.
  retune_ready_.store(false, std::memory_order_relaxed);
  rr_estimate_Ohm_.store(0.0f, std::memory_order_relaxed);
  models_[active_ ^ 1].reset();
  models_[active_].reset();
  models_[active_].emplace(motor, config_, board_);
  model_ready_.store(true, std::memory_order_release);
}

template <typename T>
void Drive<T>::retune() noexcept {
  if (!tracking_ || !model_ready_.load(std::memory_order_acquire) ||
      retune_ready_.load(std::memory_order_acquire)) {
    return;  // not tracking, no model, or the last retune not yet taken
  }
  const uint32_t k = tick_published_.load(std::memory_order_relaxed);
  if (Real(uint32_t(k - last_retune_tick_)) * config_.sample_period_s <
      config_.rr_retune_interval_s) {
    return;
  }
  const MotorModel<T>& now = *models_[active_];
  const Real estimate_Ohm = Real(rr_estimate_Ohm_.load(std::memory_order_relaxed));
  if (!(estimate_Ohm > 0) ||
      (config_.rr_retune_share > 0 &&
       std::abs(estimate_Ohm / now.motor.Rr_Ohm - 1) < config_.rr_retune_share)) {
    return;
  }
  const std::optional<control::MotorParameters> record = bank_.record();
  if (!record) return;
  control::MotorParameters motor = now.motor;
  motor.Rr_Ohm = estimate_Ohm;
  models_[active_ ^ 1].reset();
  models_[active_ ^ 1].emplace(motor, config_, board_, record->Rr_Ohm);
  last_retune_tick_ = k;
  ++retunes_;
  retune_ready_.store(true, std::memory_order_release);
}

template <typename T>
void Drive<T>::plan_commissioning() noexcept {
  const std::optional<Nameplate> nameplate = bank_.nameplate();
  if (!nameplate) {
    bank_.answer(ParameterStatus::not_set);
    return;
  }
  const Real v_bus_V = Real(bank_.access().value);
  const bool rotate = bank_.access().field == 1;
  std::optional<InertiaPlan> rotating;
  if (rotate) {
    rotating = plan_inertia_test(*nameplate, config_.i_max_A, v_bus_V, config_.sample_period_s,
                                 board_.encoder_counts_per_rev);
  }
  identifier_.emplace(
      plan_identification(*nameplate, config_.i_max_A, v_bus_V, config_.sample_period_s), rotating);
  bank_.answer(ParameterStatus::ok);
}

template <typename T>
void Drive<T>::adopt_commissioning() noexcept {
  // The tick let go of the model when it asked; the identifier has finished.
  const control::MotorParameters motor = commissioned_motor(
      identifier_->electrical(), *bank_.nameplate(), bank_.record(), identifier_->mechanics());
  const ParameterStatus status = bank_.adopt(motor, hw_.store);
  if (const auto record = bank_.record()) {  // the new motor, or the old one if refused
    rebuild(*record);
  } else {
    models_[0].reset();
    models_[1].reset();
  }
  bank_.answer(status);
}

template <typename T>
std::optional<control::MotorParameters> Drive<T>::motor() const noexcept {
  return bank_.record();
}

template <typename T>
void Drive<T>::shut_down(uint64_t k) noexcept {
  pwm_off();
  supervisor_.shut_down(k);
  record_.state = supervisor_.state();
  if (hw_.can != nullptr) {
    telemetry_.final_heartbeat(*hw_.can, supervisor_.status(), supervisor_.machine());
  }
  write_line(config_.timing_output_line, false);
}

template void Drive<float>::service() noexcept;
template void Drive<double>::service() noexcept;
template std::optional<control::MotorParameters> Drive<float>::motor() const noexcept;
template std::optional<control::MotorParameters> Drive<double>::motor() const noexcept;
template void Drive<float>::shut_down(uint64_t) noexcept;
template void Drive<double>::shut_down(uint64_t) noexcept;

}  // namespace imd::firmware
