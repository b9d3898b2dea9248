#pragma once
/// The rotating step of the commissioning (docs/identification.md, "Inertia and friction"):
/// after the standstill steps, the motor is field oriented on the identified rotor time
/// constant, fluxed, accelerated by a constant torque-producing current to a test speed, left to
/// coast with the field on and no torque, and braked back to rest. From rest, the mechanics
/// J dw/dt = Te - B w integrate twice to
///   J theta(t) + B Int theta dt = Int Int Te dt,
/// one equation per instant that needs no speed, only the encoder's angle and the torque of
/// the current model. The ends of the acceleration and of the coast give two such equations;
/// they solve for J and B. A rotor that does not turn (a locked or heavily loaded shaft) skips
/// the step and leaves the mechanics unmeasured. Tick context, T = float on the MCU.
#include <algorithm>
#include <cstdint>
#include <numbers>

#include "control/frames.hpp"
#include "control/real.hpp"
#include "firmware/duration_ticks.hpp"
#include "firmware/identification/compensated_sum.hpp"
#include "firmware/identification/standstill_identifier.hpp"

namespace imd::firmware {

enum class InertiaStep : uint8_t { flux_up, accelerate, coast, brake, ramp_down, done, failed };

enum class InertiaOutcome : uint8_t {
  running,
  measured,         ///< J and B identified
  no_motion,        ///< the rotor did not reach a fifth of the test speed: mechanics kept
  voltage_limit,    ///< the current loop ran out of voltage
  implausible,      ///< J not positive or not finite
  wrong_direction,  ///< the encoder counts against the phase sequence (swap two phases or A/B)
  overspeed,        ///< the speed passed twice the test speed: the field is not oriented
  not_at_rest,      ///< turning when the step began, or not braked to rest in time
  stalled,          ///< the speed settled below the test speed (load, or a field not oriented)
};

/// What the rotating step is planned from besides the standstill result (Real, outside the
/// tick; the rules are in plan_inertia_test()).
struct InertiaPlan {
  Real period_s = Real(1e-4);
  Real rad_per_count = 0.0;      ///< the encoder's mechanical angle per count
  Real omega_rated_rad_s = 0.0;  ///< electrical, 2 pi f_rated
  Real v_phase_peak_V = 0.0;     ///< rated phase voltage, peak
  Real i_limit_A = 0.0;          ///< the test's current magnitude limit (peak)
  Real v_limit_V = 0.0;          ///< the loop's output limit (linear SVPWM range)
  Real J_guess_kgm2 = 0.0;       ///< the inertia the torque is sized on (catalogue)
  int pole_pairs = 1;
  Real accelerate_s = 1.0;       ///< planned acceleration time with J_guess
  Real max_accelerate_s = 30.0;  ///< beyond this with no motion: skipped
  Real max_coast_s = 10.0;
  Real max_brake_extra_s = 1.0;  ///< the brake may take the acceleration's time plus this
  Real crossover_rad_s = Real(2.0 * 3.14159265358979 * 200.0);  ///< current loop bandwidth
};

/// The plan in the tick's arithmetic, converted outside the tick (the rotating step is built
/// in the tick, when the standstill steps end, and must not touch double there).
template <typename T>
struct InertiaSettings {
  explicit InertiaSettings(const InertiaPlan& p)
      : period_s(T(p.period_s)),
        rad_per_count(T(p.rad_per_count)),
        omega_rated_rad_s(T(p.omega_rated_rad_s)),
        v_phase_peak_V(T(p.v_phase_peak_V)),
        i_limit_A(T(p.i_limit_A)),
        v_limit_V(T(p.v_limit_V)),
        J_guess_kgm2(T(p.J_guess_kgm2)),
        pole_pairs(T(p.pole_pairs)),
        accelerate_s(T(p.accelerate_s)),
        // At most a twentieth of the sample rate: the 1.5 periods of delay then cost 27 deg.
        crossover_rad_s(
            T(std::min(p.crossover_rad_s, 2 * std::numbers::pi_v<Real> / (20 * p.period_s)))),
        // Whole ticks by duration_ticks: a plain quotient in float can fall a tick short.
        max_accelerate_ticks(uint32_t(duration_ticks(p.max_accelerate_s, p.period_s))),
        max_coast_ticks(uint32_t(duration_ticks(p.max_coast_s, p.period_s))),
        ramp_ticks(uint32_t(duration_ticks(Real(0.05), p.period_s))),
        brake_extra_ticks(uint32_t(duration_ticks(p.max_brake_extra_s, p.period_s))) {}
  T period_s, rad_per_count, omega_rated_rad_s, v_phase_peak_V, i_limit_A, v_limit_V;
  T J_guess_kgm2, pole_pairs, accelerate_s, crossover_rad_s;
  uint32_t max_accelerate_ticks, max_coast_ticks, ramp_ticks, brake_extra_ticks;
};

template <typename T>
struct Mechanics {
  T J_kgm2 = T(0), friction_Nms = T(0);
};

template <typename T>
class InertiaIdentifier {
 public:
  using Vec2 = control::Vec2<T>;

  /// Sizes the test from the plan and the identified electrical parameters (tick context: a
  /// few divisions and square roots, once).
  InertiaIdentifier(const InertiaSettings<T>& plan, const StandstillResult<T>& motor) noexcept;

  /// One tick: the measured current and the encoder's counts over the last period in; the
  /// alpha-beta voltage out (acting over the period after next).
  Vec2 step(const Vec2& i_A, int32_t encoder_delta_counts) noexcept;

  InertiaStep current_step() const noexcept { return step_; }
  InertiaOutcome outcome() const noexcept { return outcome_; }
  bool finished() const noexcept {
    return step_ == InertiaStep::done || step_ == InertiaStep::failed;
  }
  T fraction() const noexcept;
  /// Valid when the outcome is measured.
  const Mechanics<T>& result() const noexcept { return result_; }
  uint32_t ticks_in(InertiaStep s) const noexcept { return ticks_in_[int(s)]; }
  /// The test's operating point, for the report.
  T test_speed_rad_s() const noexcept { return omega_test_rad_s_; }
  T torque_Nm() const noexcept { return k_torque_Nm_per_A_ * i_q_A_; }

 private:
  void enter(InertiaStep s) noexcept {
    step_ = s;
    ticks_ = 0;
  }
  void stop(InertiaOutcome why) noexcept;
  /// The end of the acceleration or of the coast: one row of the two equations.
  void take_row(int row) noexcept;
  void solve() noexcept;

  // Sized at construction.
  T period_s_, rad_per_count_, pole_pairs_, v_limit_V_;
  T Lm2_over_Lr_H_, tau_r_s_, sigma_Ls_H_, kp_Ohm_, ki_T_Ohm_, flux_decay_;
  T i_d_A_, i_q_A_, omega_test_rad_s_, k_torque_Nm_per_A_;
  uint32_t flux_ticks_, max_accelerate_ticks_, max_coast_ticks_, ramp_ticks_, brake_extra_ticks_;

  InertiaStep step_ = InertiaStep::flux_up;
  InertiaOutcome outcome_ = InertiaOutcome::running;
  uint32_t ticks_ = 0, ticks_in_[7] = {};
  uint32_t accelerate_ticks_ = 0;
  // The field frame: its angle, the current model's flux (as Lm/Lr psi_r) and the loop.
  T theta_e_rad_ = T(0), omega_e_rad_s_ = T(0), slip_rad_s_ = T(0), lambda_Wb_ = T(0);
  Vec2 integral_V_ = Vec2::Zero();
  int saturated_ticks_ = 0;
  T i_d_ref_A_ = T(0);
  // The speed over 10 ms blocks of encoder counts.
  int32_t block_counts_ = 0;
  uint32_t block_ticks_ = 0;
  T omega_block_rad_s_ = T(0), omega_brake_from_rad_s_ = T(0), omega_coast_from_rad_s_ = T(0);
  // The integrals from rest: counts (exact), Int theta, Int Te, Int Int Te.
  int32_t counts_ = 0;
  int32_t half_time_counts_ = 0;  ///< counts_ at half the acceleration's time limit
  CompensatedSum<T> int_theta_, int_torque_, int2_torque_;
  T row_theta_[2] = {}, row_int_theta_[2] = {}, row_int2_torque_[2] = {};
  Mechanics<T> result_;
};

}  // namespace imd::firmware
