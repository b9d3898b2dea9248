#include "firmware/supervisor.hpp"

#include <algorithm>
#include <cmath>

#include "firmware/duration_ticks.hpp"

namespace imd::firmware {
namespace {

/// Ticks since an event, in 32 bits (5 days at 10 kHz), saturating.
uint32_t saturated_ticks(uint64_t ticks) noexcept {
  return ticks < UINT32_MAX ? static_cast<uint32_t>(ticks) : UINT32_MAX;
}

}  // namespace

template <typename T>
Supervisor<T>::Supervisor(const DriveConfig& config, const SupervisorWiring& wiring,
                          const ReferenceSource<T>* references, LawRegistry<T>* laws,
                          const Magnetizer<T>* magnetizer, bool predicts_latency,
                          bool calibrated) noexcept
    : commands_over_can_(config.commands_over_can),
      auto_enable_(config.auto_enable),
      enable_input_line_(config.enable_input_line),
      wiring_(wiring),
      commanded_(T(config.flux2_ref_Wb2), T(config.stator_flux2_ref_Wb2)),
      references_(config.commands_over_can || references == nullptr ? commanded_ : *references),
      laws_(laws),
      magnetizer_(magnetizer),
      predicts_latency_(predicts_latency),
      // Only a board's own compiled-in config could name a law outside its image, and the
      // board's build sets it from the image (board_config.hpp).
      controller_(law_in_image(config.controller) ? config.controller : first_law_in_image()),
      decoder_(config.node_id, {float(config.protection.overspeed_rad_s),
                                float(config.min_flux2_command_Wb2), float(config.max_flux2_Wb2)}),
      ramp_(config.max_accel_rad_s2, config.sample_period_s),
      command_accel_step_rad_s_(
          SpeedRamp<T>::step(config.max_accel_rad_s2, config.sample_period_s)),
      stop_accel_step_rad_s_(SpeedRamp<T>::step(
          std::min(config.max_accel_rad_s2, config.stop_decel_rad_s2), config.sample_period_s)),
      stop_speed_rad_s_(T(config.stop_speed_rad_s)),
      stop_timeout_ticks_(duration_ticks(config.stop_timeout_s, config.sample_period_s)),
      stop_policy_(config.protection.stop),
      calibrated_(calibrated),
      record_complete_(laws != nullptr),
      record_saved_(laws != nullptr) {
  select(controller_);
  if (calibrated_) {
    machine_.go(rest_state(), TransitionReason::calibrated, 0);
    bool unused = false;
    if (auto_enable_) enable(0, unused);
  }
  status_.state = machine_.state();
}

template <typename T>
void Supervisor<T>::attach(LawRegistry<T>* laws, const Magnetizer<T>* magnetizer,
                           uint64_t k) noexcept {
  ++generation_;
  laws_ = laws;
  magnetizer_ = magnetizer;
  if (laws_ == nullptr) return;
  select(controller_);
  if (machine_.state() != DriveState::unconfigured) return;  // e.g. a fault came meanwhile
  if (machine_.go(DriveState::idle, TransitionReason::configured, k) && auto_enable_) {
    bool unused = false;
    enable(k, unused);
  }
  status_.state = machine_.state();
}

template <typename T>
void Supervisor<T>::select(ControllerKind kind) noexcept {
  controller_ = kind;
  status_.controller = static_cast<uint8_t>(kind);
  if (laws_ == nullptr) return;  // the law's traits are read when a model is attached
  controlled_flux_ = law().controlled_flux();
  lookahead_ticks_ = law().lookahead_ticks();
}

template <typename T>
void Supervisor<T>::identification_ended(uint64_t k, bool done, uint8_t failure) noexcept {
  if (machine_.state() != DriveState::identifying) return;
  status_.identify_step = done ? 4 : 5;  // kIdentifyStepValues: done, failed
  status_.identify_failure = failure;
  status_.identify_fraction = 1.0f;
  // With a result the model is replaced: unconfigured until the new one is attached.
  machine_.go(done ? DriveState::unconfigured : rest_state(),
              done ? TransitionReason::identified : TransitionReason::identification_failed, k);
  status_.state = machine_.state();
}

template <typename T>
bool Supervisor<T>::read_enable_input() const noexcept {
  const int line = enable_input_line_;
  return wiring_.gpio == nullptr || line < 0 || wiring_.gpio->read(static_cast<uint8_t>(line));
}

template <typename T>
const TickPlan<T>& Supervisor<T>::plan(uint64_t k, const Measurement<T>& m,
                                       const Estimate<T>& e) noexcept {
  enable_input_ = read_enable_input();  // before the commands: enable needs it
  v_bus_V_ = m.v_bus_V;
  bool restarted = false;
  if (wiring_.can != nullptr) receive_commands(k, restarted);
  // Running on with nothing applied since prepare(k - 1) (a command, a fault, a model attached
  // bump the generation): its plan is this tick's, whole.
  if (prepared_.k == k && prepared_.generation == generation_ && e.valid &&
      machine_.state() == DriveState::running && !fault_stop_) {
    ramp_.reset(prepared_.ramp_k1_rad_s);
    return prepared_.plan;
  }
  return replan(k, m, e, restarted);
}

template <typename T>
const TickPlan<T>& Supervisor<T>::replan(uint64_t k, const Measurement<T>& m,
                                         const Estimate<T>& e, bool restarted) noexcept {
  TickPlan<T>& p = plan_;
  p = TickPlan<T>{};
  p.mode = Mode::off;
  p.stopping = false;
  p.restarted = restarted;
  if (machine_.state() == DriveState::calibrating && m.calibration == Calibration::done) {
    calibrated_ = true;
    machine_.go(rest_state(), TransitionReason::calibrated, k);
    if (auto_enable_) enable(k + 1, p.restarted);
  }
  if (machine_.state() == DriveState::identifying) {
    p.mode = Mode::identifying;
  } else if (modulating() && e.valid) {
    references(k, e, p);
    const ControlledFlux flux = controlled_flux_;
    if (machine_.state() == DriveState::magnetizing) {
      if (magnetizer_->magnetized(e.x, p.next, flux)) {
        machine_.go(DriveState::running, TransitionReason::magnetized, k);
        law().start(e.x, magnetizer_->current_AB_A(e.x_input, p.next, flux));
      } else {
        p.mode = Mode::magnetizing;
      }
    }
    if (machine_.state() == DriveState::running || machine_.state() == DriveState::stopping) {
      p.mode = Mode::controlling;
      if (lookahead_ticks_ > 0) {
        p.ahead = references_.at_tick(k + lookahead_ticks_);
        p.ahead.omega_mech_rad_s = p.next.omega_mech_rad_s;  // through the speed ramp
        if (p.stopping) p.ahead.torque_Nm = T(0);
      }
    }
    if (fault_stop_ && status_.stop == StopCategory::dc_brake) {
      p.mode = Mode::dc_braking;
      if (k >= dc_brake_end_tick_) end_fault_stop(k, p);
    } else if (p.stopping &&
               ((ramp_.value() == T(0) && std::abs(e.x.omega_mech_rad_s) < stop_speed_rad_s_) ||
                k - stop_start_tick_ > stop_timeout_ticks_)) {
      // A stop is complete once the ramp is at zero and the motor (nearly) still.
      if (fault_stop_) {
        end_fault_stop(k, p);
      } else {
        machine_.go(DriveState::idle, TransitionReason::stopped, k);
        p.mode = Mode::off;
      }
    }
  } else if (e.valid) {
    p.next = references_.at_tick(k);  // what the drive would aim at once enabled
  }
  return p;
}

template <typename T>
SupervisedState Supervisor<T>::supervised(uint64_t k, const TickPlan<T>& p) const noexcept {
  SupervisedState s;
  s.restarted = p.restarted;
  s.modulating = modulating();
  s.enable_input = enable_input_;
  s.magnetizing = machine_.state() == DriveState::magnetizing;
  s.dc_braking = p.mode == Mode::dc_braking;
  // The counts only where they are judged: a 64-bit difference and its saturation each.
  if (s.magnetizing) s.magnetizing_ticks = saturated_ticks(k - magnetizing_start_tick_);
  s.watchdog_armed = commands_over_can_ && (machine_.state() == DriveState::magnetizing ||
                                            machine_.state() == DriveState::running);
  if (s.watchdog_armed) s.command_silence_ticks = saturated_ticks(k - last_command_tick_);
  return s;
}

template <typename T>
inline void Supervisor<T>::references(uint64_t k, const Estimate<T>& e, TickPlan<T>& p) noexcept {
  // References at x_input's step (now) and the step after (next), the speed through the ramp.
  // Until the drive runs, a limited ramp follows the estimate and an unlimited one the
  // reference, so that the reaching law acts on the real error from the first running tick.
  // Stopping ramps the speed to zero at the stop deceleration.
  p.stopping = machine_.state() == DriveState::stopping;
  if (machine_.state() == DriveState::magnetizing) {
    ramp_.reset(ramp_.limited()
                    ? e.x.omega_mech_rad_s
                    : (p.stopping ? T(0) : references_.at_tick(k).omega_mech_rad_s));
  }
  T ramp_k1_rad_s;
  shaped(k, p.stopping, p.now, p.next, ramp_k1_rad_s);
  ramp_.reset(ramp_k1_rad_s);
}

template <typename T>
void Supervisor<T>::shaped(uint64_t k, bool stopping, Reference<T>& now, Reference<T>& next,
                           T& ramp_k1_rad_s) const noexcept {
  const uint64_t latency = predicts_latency_ ? 1 : 0;
  // Each tick's reference is read once: k + 1 and k + 2 serve both the ramp and the law.
  const Reference<T> at_k1 = references_.at_tick(k + 1);
  const Reference<T> at_k2 = references_.at_tick(k + 2);
  const T target_k1 = stopping ? T(0) : at_k1.omega_mech_rad_s;
  const T target_k2 = stopping ? T(0) : at_k2.omega_mech_rad_s;
  ramp_k1_rad_s = ramp_.next(ramp_.value(), target_k1);
  now = latency ? at_k1 : references_.at_tick(k);
  next = latency ? at_k2 : at_k1;
  now.omega_mech_rad_s = latency ? ramp_k1_rad_s : ramp_.value();
  next.omega_mech_rad_s = latency ? ramp_.next(ramp_k1_rad_s, target_k2) : ramp_k1_rad_s;
  if (stopping) now.torque_Nm = next.torque_Nm = T(0);
}

template <typename T>
void Supervisor<T>::prepare(uint64_t k) noexcept {
  prepared_.k = Prepared::kNotPrepared;
  // Running: plan(k + 1) neither resets the ramp nor stops (a stop begins with a command or a
  // fault, each of which bumps the generation). The plan is the one plan() builds running.
  if (machine_.state() != DriveState::running) return;
  TickPlan<T>& p = prepared_.plan;
  p.mode = Mode::controlling;
  p.stopping = false;
  p.restarted = false;
  shaped(k + 1, false, p.now, p.next, prepared_.ramp_k1_rad_s);
  if (lookahead_ticks_ > 0) {
    p.ahead = references_.at_tick(k + 1 + lookahead_ticks_);
    p.ahead.omega_mech_rad_s = p.next.omega_mech_rad_s;  // through the speed ramp
  } else {
    p.ahead = {};
  }
  prepared_.generation = generation_;
  prepared_.k = k + 1;
}

template <typename T>
bool Supervisor<T>::latch(const Trip& trip, uint64_t k, const StopContext<T>& motion) noexcept {
  ++generation_;  // the commanded speed and the ramp's limit change below
  commanded_.set_speed(T(0));  // after clear and enable, the host sends a new speed
  status_.fault_bits = static_cast<uint16_t>(status_.fault_bits | trip.bits);
  if (machine_.state() == DriveState::fault) return true;  // the first fault is kept
  StopCategory stop = stop_category(trip.bits, stop_policy_);
  // A controlled stop needs a law that runs on a magnetized motor; DC braking, motion to stop.
  const bool controlled = machine_.state() == DriveState::running ||
                          machine_.state() == DriveState::stopping;
  if (!controlled || (stop == StopCategory::dc_brake &&
                      (motion.dc_brake_ticks == 0 ||
                       !(std::abs(motion.omega_mech_rad_s) > stop_speed_rad_s_)))) {
    stop = StopCategory::sto;
  }
  if (fault_stop_) {  // an earlier fault's stop runs: STO overrides it, and so does a fault
    // that takes speed control away from an SS1 ramp (the encoder: no DC braking from here)
    const bool ramp_lost = stop == StopCategory::dc_brake && status_.stop == StopCategory::ss1;
    if (stop != StopCategory::sto && !ramp_lost) return false;
    fault_stop_ = false;
    status_.stop = StopCategory::sto;
    machine_.go(DriveState::fault, TransitionReason::fault, k);
    status_.state = DriveState::fault;
    if (wiring_.can != nullptr) wiring_.telemetry.report_fault(*wiring_.can, status_);
    return true;
  }
  if (machine_.state() == DriveState::identifying) {
    status_.identify_step = 5;     // failed
    status_.identify_failure = 5;  // aborted (by the fault)
  }
  status_.first_fault = trip.first;
  status_.first_fault_tick = k;
  status_.fault_detail = trip.detail;
  status_.stop = stop;
  if (stop == StopCategory::sto) {
    machine_.go(DriveState::fault, TransitionReason::fault, k);
  } else {
    fault_stop_ = true;
    if (machine_.state() == DriveState::running) {
      machine_.go(DriveState::stopping, TransitionReason::fault, k);
    }
    stop_start_tick_ = k;
    ramp_.set_max_step(stop_accel_step_rad_s_);
    dc_brake_end_tick_ = k + motion.dc_brake_ticks;
  }
  status_.state = machine_.state();
  if (wiring_.can != nullptr) wiring_.telemetry.report_fault(*wiring_.can, status_);
  return stop == StopCategory::sto;
}

template <typename T>
void Supervisor<T>::end_fault_stop(uint64_t k, TickPlan<T>& p) noexcept {
  fault_stop_ = false;
  machine_.go(DriveState::fault, TransitionReason::stopped, k);
  status_.state = DriveState::fault;
  p.mode = Mode::off;
}

template <typename T>
void Supervisor<T>::shut_down(uint64_t k) noexcept {
  fault_stop_ = false;  // the program ends: no stop runs on
  if (modulating()) machine_.go(DriveState::idle, TransitionReason::shutdown, k);
  status_.state = machine_.state();
}

template class Supervisor<float>;
template class Supervisor<double>;

}  // namespace imd::firmware
