#pragma once
/// The standstill identification of an unknown motor (docs/identification.md): a current loop
/// on the alpha axis holds two DC levels and steps between them; the voltages it needs, and the
/// current ripple of a square-wave voltage, give Rs, Ls, sigma Ls, tau_r and Lm^2/Lr. The
/// field stays on one axis, so the motor makes no torque and the rotor does not turn. Every
/// result comes from differences between two levels, which cancel the inverter's voltage
/// error (dead time, device drop) and the ADC's offset. Tick context, T = float on the MCU.
#include <cmath>
#include <cstdint>

#include "control/frames.hpp"
#include "firmware/identification/compensated_sum.hpp"
#include "firmware/identification/nameplate.hpp"
#include "firmware/identification/settling_detector.hpp"

namespace imd::firmware {

enum class IdentificationStep : uint8_t {
  low_level,             ///< the low DC level, until settled: V1
  high_level,            ///< the step to the high level and its transient: Rs, Ls, tau_r
  transient_inductance,  ///< the square wave on the high level: sigma Ls
  ramp_down,             ///< the current back to zero
  done,
  failed,
};

enum class IdentificationFailure : uint8_t {
  none,
  not_settled,     ///< a level did not settle within max_level_s
  voltage_limit,   ///< the loop needed more voltage than the inverter has
  implausible,     ///< a result is not positive or not finite (no motor connected?)
  no_nameplate,    ///< the record has no complete nameplate to plan the test from
  aborted,         ///< a disable command or a fault stopped it
  invalid_record,  ///< the results make no valid motor (e.g. no leakage)
};

template <typename T>
struct StandstillResult {
  T Rs_Ohm = T(0), Ls_H = T(0), sigma_Ls_H = T(0), tau_r_s = T(0), Lm2_over_Lr_H = T(0);
};

template <typename T>
class StandstillIdentifier {
 public:
  using Vec2 = control::Vec2<T>;

  explicit StandstillIdentifier(const IdentificationPlan& plan) noexcept
      : period_s_(T(plan.period_s)),
        i_low_A_(T(plan.i_low_A)),
        i_high_A_(T(plan.i_high_A)),
        kp_(T(plan.kp_Ohm)),
        ki_T_(T(plan.ki_Ohm_per_s * plan.period_s)),
        v_limit_V_(T(plan.v_limit_V)),
        hf_V_(T(plan.hf_voltage_V)),
        hf_ripple_A_(T(plan.hf_ripple_A)),
        hf_half_(plan.hf_half_period_ticks),
        hf_ticks_(plan.hf_ticks),
        window_ticks_(plan.window_ticks),
        max_level_ticks_(static_cast<uint32_t>(plan.max_level_s / plan.period_s)),
        ramp_ticks_(static_cast<uint32_t>(plan.ramp_down_s / plan.period_s) + 1) {}

  /// One tick: the measured alpha-beta current in; the alpha-beta voltage to write out (it acts
  /// over the period after next: one period of PWM latency).
  Vec2 step(const Vec2& i_A) noexcept;

  IdentificationStep current_step() const noexcept { return step_; }
  IdentificationFailure failure() const noexcept { return failure_; }
  /// Progress through the current step, 0..1.
  T fraction() const noexcept;
  bool finished() const noexcept {
    return step_ == IdentificationStep::done || step_ == IdentificationStep::failed;
  }
  /// Valid once done.
  const StandstillResult<T>& result() const noexcept { return result_; }
  /// Ticks spent in each step so far (for the report).
  uint32_t ticks_in(IdentificationStep s) const noexcept { return ticks_in_[int(s)]; }

 private:
  struct Level {  // the hold after a level settled
    CompensatedSum<T> v_V, i_A;
    uint32_t ticks = 0, hold_ticks = 0;
  };

  Vec2 current_loop(const Vec2& i_A, T i_ref_alpha_A) noexcept;
  void enter(IdentificationStep s) noexcept;
  /// Window bookkeeping of a level; true when its hold is complete.
  bool level(const Vec2& i_A, T v_acting_V, T i_ref_A, T i_from_A) noexcept;
  void fail(IdentificationFailure why) noexcept {
    failure_ = why;
    enter(IdentificationStep::failed);
  }
  void finish() noexcept;

  T period_s_, i_low_A_, i_high_A_, kp_, ki_T_, v_limit_V_, hf_V_, hf_ripple_A_;
  int hf_half_, hf_ticks_, window_ticks_;
  uint32_t max_level_ticks_, ramp_ticks_;

  IdentificationStep step_ = IdentificationStep::low_level;
  IdentificationFailure failure_ = IdentificationFailure::none;
  uint32_t ticks_ = 0;  ///< in the current step
  uint32_t ticks_in_[6] = {};
  Vec2 integral_V_ = Vec2::Zero();
  Vec2 u_written_V_ = Vec2::Zero();  ///< the command of the last tick: acts from the next
  Vec2 u_acting_V_ = Vec2::Zero();   ///< the command acting over this period
  int saturated_ticks_ = 0;

  // Levels: window means for the settling detector, then the hold.
  SettlingDetector<T> settle_;
  CompensatedSum<T> window_v_;
  int window_fill_ = 0;
  bool arrived_ = true;  ///< the current stayed near its reference over this window
  bool holding_ = false;
  Level hold_;
  T v_low_V_ = T(0), i_low_meas_A_ = T(0);
  // The high level's transient: moments of the acting voltage and the current from the step.
  CompensatedSum<T> sv_, stv_, si_, sti_, k0_, k1v_, k1i_;
  // The square wave: least squares of the current steps on the voltage steps.
  CompensatedSum<T> sdd_, sdi_;
  T hf_bias_V_ = T(0), i_previous_A_ = T(0), delta_acting_V_ = T(0), delta_written_V_ = T(0);
  T v_high_V_ = T(0), i_high_meas_A_ = T(0);
  T ramp_from_A_ = T(0);
  StandstillResult<T> result_;
};

}  // namespace imd::firmware
