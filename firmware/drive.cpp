#include "firmware/drive.hpp"

#include "control/svpwm.hpp"
#include "firmware/duration_ticks.hpp"

#include <numbers>

namespace imd::firmware {
namespace {
template <typename T>
std::optional<MotorModel<T>> build(const std::optional<MotorRecord>& record,
                                   const DriveConfig& config, const BoardScales& board) {
  if (!record) return std::nullopt;
  return std::optional<MotorModel<T>>(std::in_place, record->motor, config, board);
}
}  // namespace

template <typename T>
Drive<T>::Drive(const std::optional<MotorRecord>& record, const DriveConfig& config,
                const DrivePeripherals& peripherals, const DriveSubstitutes<T>& substitutes)
    : config_(config),
      hw_(peripherals),
      substitutes_(substitutes),
      board_{peripherals.pwm, Real(peripherals.encoder.counts_per_rev()),
             Real(peripherals.adc.scale().phase_A_per_code)},
      board_sensing_(peripherals.adc, peripherals.encoder,
                     {config.adc_calibration_ticks, config.adc_offset_limit_A}),
      sensing_(substitutes.sensing != nullptr ? *substitutes.sensing : board_sensing_),
      bank_(record),
      models_{build<T>(record, config, board_), std::nullopt},
      model_ready_(models_[0].has_value()),
      attached_(models_[0] ? &*models_[0] : nullptr),
      tracking_(config.rotor_resistance_tracking && substitutes.power_stage == nullptr),
      protection_(config),
      telemetry_(config.node_id, peripherals.timer.period_ns(), config.telemetry_rate_Hz,
                 static_cast<float>(Real(1e9) / Real(peripherals.timer.execution_clock_Hz()))),
      supervisor_(config, {peripherals.can, peripherals.gpio, telemetry_, &bank_},
                  substitutes.references, attached_ ? &attached_->laws : nullptr,
                  attached_ ? &attached_->magnetizer : nullptr,
                  config.compensate_latency && config.pwm_latency_ticks > 0,
                  config.adc_calibration_ticks <= 0),
      clock_Hz_(peripherals.timer.execution_clock_Hz()),
      ns_per_count_(static_cast<float>(Real(1e9) / Real(clock_Hz_))),
      rad_s_per_count_(T(2 * std::numbers::pi_v<Real> /
                         (board_.encoder_counts_per_rev * config.sample_period_s))),
      limited_(limited_window_ticks(config)),
      brake_release_ticks_(duration_ticks(config.brake_release_time_s, config.sample_period_s)) {
  protection_.set_clock(clock_Hz_);
  hw_.pwm.disable();
  supervisor_.status().reset_cause = static_cast<uint8_t>(peripherals.reset_cause);
  // A fitted brake holds from power-up (its line not driven): the first heartbeat must say so.
  supervisor_.status().brake_engaged = config.brake_output_line >= 0;
}

template <typename T>
void Drive<T>::on_tick() noexcept {
  write_line(config_.timing_output_line, true);
  record_.stages_timed = ++ticks_since_timed_ >= config_.stage_timing_period_ticks;
  if (record_.stages_timed) ticks_since_timed_ = 0;
  StageClock clock(hw_.timer, record_.stage_counts, record_.stages_timed);
  const uint64_t k = hw_.timer.tick_count();
  const Measurement<T> m = sensing_.measure(supervisor_.state() == DriveState::calibrating);
  clock.lap(Stage::sense);
  MotorModel<T>* const model = this->model(k);
  const Vec2 u_acted_V = u_last_period_V_;  // over [k-1, k]: the tracker's, after the write
  const Estimate<T> e = estimate(m, model);
  clock.lap(Stage::estimate);
  const TickPlan<T>& plan = supervisor_.plan(k, m, e);  // valid until prepare(k) below
  // A hardware trip is forgotten only when its fault is cleared (and found again at once if
  // the comparator still holds the break input).
  if (plan.restarted) hw_.pwm.clear_trip();
  clock.lap(Stage::supervise);
  const LawOutput<T> u = law(plan, e, m.v_bus_V, model);
  clock.lap(Stage::law);
  const Modulation<T> out = modulate(plan, u, e, m, model);
  clock.lap(Stage::modulate);
  const bool law_voltage = actuate(out, model);
  const Trip overrun = check_budget(clock.lap_total(Stage::actuate));
  if (hw_.watchdog != nullptr) hw_.watchdog->feed();  // the PWM is written: the tick lives
  // Every trip decision follows the write: hal::Pwm latches the duties for the next period, so
  // a trip that turns the PWM off in this tick keeps them from ever acting, as before the write.
  SupervisedState supervised = supervisor_.supervised(k, plan);
  supervised.brake_may_hold = config_.brake_output_line >= 0 &&
      (!brake_line_level_ || k < brake_released_tick_ + brake_release_ticks_);
  Trip trip = protection_.check(m, e, supervised, u, out, e.valid ? &model->checks : nullptr);
  // The power stage's own over-current trip already turned the outputs off: latch it.
  if (hw_.pwm.tripped()) trip.add(FaultCode::overcurrent, kHardwareTripDetail);
  react(k, e, out, trip, overrun, law_voltage, model);
  clock.lap(Stage::protect);
  after_write(m, e, plan.mode == Mode::controlling && model != nullptr, u_acted_V, model);
  publish(k, m, e, plan, u, out, model);
  supervisor_.prepare(k);  // the next tick's plan, off the path to its write
  if (adopt_pending_ || supervisor_.state() == DriveState::identifying) end_identification(k);
  if (bank_.apply_wanted()) release_model();
  clock.lap(Stage::publish);
  write_line(config_.timing_output_line, false);
}

template <typename T>
inline MotorModel<T>* Drive<T>::model(uint64_t k) noexcept {
  if (attached_ == nullptr && model_ready_.load(std::memory_order_acquire)) {
    attached_ = &*models_[active_];
    supervisor_.attach(&attached_->laws, &attached_->magnetizer, k);
  } else if (attached_ != nullptr && retune_ready_.load(std::memory_order_acquire)) {
    // The model on the tracked rotor resistance takes over from this tick, state and all.
    MotorModel<T>& next = *models_[active_ ^ 1];
    next.continue_from(*attached_);
    active_ ^= 1;
    attached_ = &next;
    supervisor_.attach(&next.laws, &next.magnetizer, k);
    retune_ready_.store(false, std::memory_order_release);  // the old one is the service's
  }
  return attached_;
}

template <typename T>
void Drive<T>::release_model() noexcept {
  attached_ = nullptr;
  supervisor_.attach(nullptr, nullptr, 0);
  model_ready_.store(false, std::memory_order_relaxed);
  bank_.request_apply();  // release: from here the service loop owns the models
}

template <typename T>
Modulation<T> Drive<T>::identify(const Measurement<T>& m) noexcept {
  if constexpr (kCommissioningInImage) {
    if (!m.valid || !identifier_) return {};
    const Modulation<T> out = direct_modulation(
        identifier_->step(m.i_alphabeta_A, m.encoder_delta_counts), m.v_bus_V);
    supervisor_.identification_progress(identifier_->step_code(),
                                        static_cast<float>(identifier_->fraction()));
    return out;
  } else {
    return {};  // never identifying: the supervisor refuses the command (not_in_image)
  }
}

template <typename T>
Modulation<T> Drive<T>::dc_brake(const Measurement<T>& m, const Estimate<T>& e,
                                 MotorModel<T>& model) noexcept {
  Modulation<T> out = direct_modulation(
      model.dc_brake.step(m.i_alphabeta_A, model.limits.v_max_V(m.v_bus_V)), m.v_bus_V);
  // What acts, for the observers (their position is the failed encoder's: of no use now).
  out.u_acting_alphabeta_V = out.u_alphabeta_V;
  out.v_acting_AB_V =
      control::Rotation<T>::from_angle(T(model.motor.pole_pairs) * e.x.theta_mech_rad)
          .apply_inverse(out.u_alphabeta_V);
  return out;
}

template <typename T>
void Drive<T>::end_identification(uint64_t k) noexcept {
  if constexpr (kCommissioningInImage) {
    if (adopt_pending_) {  // a parameter read was in flight at the end: hand over now
      adopt_pending_ = !bank_.submit({protocol::ParameterOp::identified, 0, 0.0f, true});
      return;
    }
    if (supervisor_.state() != DriveState::identifying || !identifier_ ||
        !identifier_->finished()) {
      return;
    }
    const bool done = identifier_->succeeded();
    supervisor_.identification_ended(k, done, identifier_->failure_code());
    pwm_off();
    if (!done) return;
    // The new record replaces the model: the service loop builds it from the result.
    attached_ = nullptr;
    supervisor_.attach(nullptr, nullptr, k);
    model_ready_.store(false, std::memory_order_relaxed);
    adopt_pending_ = !bank_.submit({protocol::ParameterOp::identified, 0, 0.0f, true});
  }
}

template <typename T>
inline Estimate<T> Drive<T>::estimate(const Measurement<T>& m, MotorModel<T>* model) noexcept {
  // While the commissioning drives the motor the model's observers have nothing to follow.
  if (!m.valid || model == nullptr || supervisor_.state() == DriveState::identifying) return {};
  return observe(m, *model);
}

template <typename T>
inline Estimate<T> Drive<T>::observe(const Measurement<T>& m, MotorModel<T>& model) noexcept {
  // The board's own estimator is called as its final class: a direct call the compiler may
  // inline, not a virtual one (likewise its power stage in modulate and actuate).
  Estimate<T> e = substitutes_.estimator != nullptr ? substitutes_.estimator->estimate(m)
                                                    : model.observers.estimate(m);
  model.predictor.set_input_state(e);
  // The rotor resistance moves only while a law runs on a magnetized motor (decided now, on the
  // state the estimate was made in; the tracker steps after the PWM write).
  tracker_due_ = true;
  tracker_adapts_ = tracking_ && supervisor_.state() == DriveState::running;
  return e;
}

template <typename T>
inline void Drive<T>::after_write(const Measurement<T>& m, const Estimate<T>& e,
                                  bool law_stepped, const Vec2& u_acted_V,
                                  MotorModel<T>* model) noexcept {
  if (observers_due_) {  // the observers advance over [k, k+1] with the input acting on it
    observers_due_ = false;
    if (substitutes_.estimator != nullptr) {
      substitutes_.estimator->advance(v_acting_V_);
    } else if (const auto* next = model->predictor.next_state()) {  // latency: step taken
      model->observers.advance_to(*next);  // by the predictor (same model, state and voltage)
    } else {
      model->observers.advance(v_acting_V_);
    }
  }
  if (law_stepped) supervisor_.law().after_write(e.x_input, model->limits.v_max_V(m.v_bus_V));
  if (tracker_due_) {
    tracker_due_ = false;
    model->rotor_resistance.step(m.i_alphabeta_A, e.x.i_s_AB_A, e.x.omega_mech_rad_s,
                                 T(m.encoder_delta_counts) * rad_s_per_count_, u_acted_V,
                                 tracker_adapts_);
  }
}

template <typename T>
inline LawOutput<T> Drive<T>::law(const TickPlan<T>& plan, const Estimate<T>& e, T v_bus_V,
                                  MotorModel<T>* model) noexcept {
  record_.law.speed_saturated = record_.law.flux_saturated = record_.law.iol_boundary = false;
  record_.law.voltage_limited = false;
  record_.law.limit = Limitation::none;
  // The commissioning drives the motor itself; a law would run on no estimate.
  // DC braking has no law either: the failed encoder's estimate is of no use to one.
  if (plan.mode == Mode::off || plan.mode == Mode::identifying ||
      plan.mode == Mode::dc_braking || model == nullptr) {
    return {};
  }
  const control::InputDisk<T> feasible = model->limits.feasible(e.x_input, v_bus_V);
  if (plan.mode == Mode::magnetizing) {
    return model->magnetizer.step(e.x_input, plan.next, supervisor_.controlled_flux(), feasible);
  }
  const T v_max_V = model->limits.v_max_V(v_bus_V);
  const LawInput<T> in{e, plan.now, plan.next, plan.ahead, plan.stopping, feasible, v_max_V};
  return supervisor_.law().step(in, record_.law);
}

template <typename T>
inline Modulation<T> Drive<T>::modulate(const TickPlan<T>& plan, const LawOutput<T>& u,
                                        const Estimate<T>& e, const Measurement<T>& m,
                                        MotorModel<T>* model) noexcept {
  if (plan.mode == Mode::identifying) return identify(m);
  if (plan.mode == Mode::off || model == nullptr) return {};
  if (plan.mode == Mode::dc_braking) return dc_brake(m, e, *model);
  if (substitutes_.power_stage != nullptr) {
    return substitutes_.power_stage->modulate(u, e.x_input, m.v_bus_V);
  }
  return model->svpwm.modulate(u, e.x_input, m.v_bus_V);
}

template <typename T>
inline bool Drive<T>::actuate(const Modulation<T>& out, MotorModel<T>* model) noexcept {
  if (supervisor_.state() == DriveState::identifying ||
      (out.direct && supervisor_.modulating() && model != nullptr)) {
    hw_.pwm.set_duties(out.duty);  // the commissioning's or DC braking's own voltage
    hw_.pwm.enable();
    return supervisor_.state() != DriveState::identifying;
  }
  if (supervisor_.modulating() && model != nullptr) {
    if (substitutes_.power_stage != nullptr) {
      substitutes_.power_stage->write(out);
    } else {
      model->svpwm.write(out);
    }
    return true;
  }
  if (hw_.pwm.enabled()) pwm_off();
  return false;
}

template <typename T>
inline void Drive<T>::react(uint64_t k, const Estimate<T>& e, const Modulation<T>& out,
                            const Trip& trip, const Trip& overrun, bool law_voltage,
                            MotorModel<T>* model) noexcept {
  // A fault takes its stop: STO turns the PWM off now, before the written duties act; a
  // controlled stop (SS1, DC braking) starts from the next tick, this tick's output acting.
  if (trip.any()) {
    StopContext<T> motion;
    if (model != nullptr && e.valid && substitutes_.power_stage == nullptr &&
        !supervisor_.fault_stopping()) {
      motion.omega_mech_rad_s = e.x.omega_mech_rad_s;
      motion.dc_brake_ticks = model->dc_brake.begin(e.x.omega_mech_rad_s);
    }
    if (supervisor_.latch(trip, k, motion)) pwm_off();
  }
  if (overrun.any()) {
    supervisor_.latch(overrun, k);  // STO: the late duties never act
    pwm_off();
  }
  const bool acting = law_voltage && hw_.pwm.enabled();
  v_applied_V_ = acting ? out.v_acting_AB_V : Vec2::Zero();
  // The input acting over [k, k+1], for the observers: they advance after the PWM write.
  if (e.valid && model != nullptr) {
    v_acting_V_ = model->predictor.written(v_applied_V_);
    observers_due_ = true;
    u_last_period_V_ =
        model->predictor.written_stator(acting ? out.u_acting_alphabeta_V : Vec2::Zero());
  } else {
    u_last_period_V_ = Vec2::Zero();
  }
}

template <typename T>
inline Trip Drive<T>::check_budget(uint32_t counts) noexcept {
  const float exec_ns = float(counts) * ns_per_count_;  // within float's 2^-24
  record_.exec_ns = exec_ns < 4e9f ? static_cast<uint32_t>(exec_ns) : UINT32_MAX;
  execution_.add(record_.exec_ns);
  const Trip overrun = protection_.over_budget(counts);
  if (overrun.any()) ++execution_.overruns;
  return overrun;
}

template <typename T>
inline void Drive<T>::publish(uint64_t k, const Measurement<T>& m, const Estimate<T>& e,
                              const TickPlan<T>& plan, const LawOutput<T>& u,
                              const Modulation<T>& out, MotorModel<T>* model) noexcept {
  TickRecord<T>& r = record_;
  r.tick = k;
  r.v_bus_V = m.v_bus_V;
  r.voltage_clipped = out.clipped;
  if (e.valid && model != nullptr) {
    const ControlledFlux flux = supervisor_.controlled_flux();
    r.i_alphabeta_A = m.i_alphabeta_A;
    r.omega_est_rad_s = e.x.omega_mech_rad_s;
    r.theta_est_rad = e.x.theta_mech_rad;
    r.flux_est_AB_Wb = e.x.flux_r_AB_Wb;
    r.flux2_est_Wb2 = e.x.flux_r_AB_Wb.squaredNorm();
    r.controlled_flux2_Wb2 = model->magnetizer.flux2_Wb2(e.x, flux);
    r.load_est_Nm = e.load_Nm;
    r.i_s_est_AB_A = e.x.i_s_AB_A;
    r.rr_est_Ohm = model->rotor_resistance.Rr_Ohm();
    r.rr_adapting = model->rotor_resistance.adapting();
    r.rr_scale = model->rotor_resistance.scale();
    rr_estimate_Ohm_.store(static_cast<float>(r.rr_est_Ohm), std::memory_order_relaxed);
    tick_published_.store(static_cast<uint32_t>(k), std::memory_order_relaxed);
    r.v_AB_V = v_applied_V_;
    r.omega_ref_rad_s = plan.next.omega_mech_rad_s;
    r.flux2_ref_Wb2 = plan.next.flux2_Wb2;
    r.controlled_flux2_ref_Wb2 = Magnetizer<T>::flux2_ref_Wb2(plan.next, flux);
    r.u_alphabeta_V = out.u_alphabeta_V;
    if (plan.mode != Mode::off) r.i_cmd_AB_A = u.i_cmd_AB_A;
  }
  DriveStatus& status = supervisor_.status();
  status.state = supervisor_.state();
  if (status.state == DriveState::running) {
    if (record_.law.limit == Limitation::input && model != nullptr) {  // which limit binds
      record_.law.limit = model->limits.binding(e.x_input, m.v_bus_V, u.v_AB_V);
    }
    limited_.update(record_.law.limit);
  } else {
    limited_.reset();  // stopping, stopped or faulted: nothing to reach
  }
  status.limited = limited_.limited();
  r.limited = status.limited;
  status.command_counter = supervisor_.decoder().last_counter();
  status.rejected_commands = supervisor_.decoder().rejected_total();
  r.state = status.state;
  r.fault = status.first_fault;
  r.fault_bits = status.fault_bits;
  if (hw_.can != nullptr) {
    status.can_bus_off = hw_.can->bus_off();
    telemetry_.publish(k, *hw_.can, r, status, supervisor_.machine(), execution_,
                       config_.protection.tick_budget_ns);
  }
  const bool faulted = status.state == DriveState::fault || supervisor_.fault_stopping();
  if (faulted != fault_line_level_) {
    write_line(config_.fault_output_line, faulted);  // on change only: a system call on Linux
    fault_line_level_ = faulted;
  }
  // The holding brake: released only while a law controls the motion (and the PWM is on).
  const bool release = supervisor_.brake_released() && hw_.pwm.enabled();
  // The heartbeat reports a brake only where one is fitted: no line, nothing holds the rotor.
  status.brake_engaged = config_.brake_output_line >= 0 && !release;
  r.brake_engaged = !release;
  r.stop = status.stop;
  if (release != brake_line_level_) {
    write_line(config_.brake_output_line, release);
    brake_line_level_ = release;
    if (release) brake_released_tick_ = k;
  }
}

template <typename T>
void Drive<T>::pwm_off() noexcept {
  hw_.pwm.disable();
  // Neutral duties: a timer that starts from its last duties applies nothing stale on enable.
  hw_.pwm.set_duties({0.5f, 0.5f, 0.5f});
}

template <typename T>
void Drive<T>::write_line(int line, bool level) noexcept {
  if (hw_.gpio != nullptr && line >= 0) hw_.gpio->write(static_cast<uint8_t>(line), level);
}

template class Drive<float>;
template class Drive<double>;

}  // namespace imd::firmware
