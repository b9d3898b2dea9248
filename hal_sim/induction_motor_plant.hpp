#pragma once
/// Continuous model (1) of paper 000 in the stationary (alpha-beta) frame, integrated with RK4:
///
///   dPhi/dt = -alpha Phi + p w J Phi + alpha Lm I
///   dI/dt   = alpha beta Phi - p beta w J Phi - gamma I + u / sigma
///   dw/dt   = (T_e - c w - T_L) / J,   T_e = 3/2 p (Lm/Lr) I^T J Phi
///   dth/dt  = w
///
/// The stator can be voltage-fed (u held over the period, as an inverter applies it), voltage-
/// fed through the ideal analog inner feedback (2) evaluated continuously inside the
/// integration, or current-fed (I~ held in the rotor-aligned frame, as paper 001 assumes).
///
/// Phases of the star-connected stator can be open (a fault): their current is then held at zero
/// by their floating terminals (set_open_phases).
#include <Eigen/Core>
#include <cstddef>
#include <optional>

#include "control/frames.hpp"
#include "control/motor_parameters.hpp"
#include "hal_sim/plant_integrator.hpp"

namespace imd::sim {

using Vec2 = control::Vec2<double>;

/// Plant state in the stationary frame.
struct PlantState {
  Vec2 flux_r_alphabeta_Wb = Vec2::Zero();  ///< rotor flux Phi
  Vec2 i_s_alphabeta_A = Vec2::Zero();      ///< stator current I
  double omega_mech_rad_s = 0.0;            ///< mechanical speed w
  double theta_mech_rad = 0.0;              ///< mechanical position th
};

/// Unit vector of phase `phase`'s axis (0..2: a, b, c) in alpha-beta, (cos 2 pi k/3,
/// sin 2 pi k/3). With the amplitude-invariant Clarke transform (control/svpwm.hpp), that phase's
/// current is the projection of the alpha-beta current on it.
Vec2 phase_axis(int phase) noexcept;

/// A stator-voltage error that depends on the stator current (the inverter's dead time and
/// device drop), evaluated at every integration stage.
class CurrentDependentVoltage {
 public:
  virtual Vec2 error_V(const Vec2& i_s_alphabeta_A) const noexcept = 0;

 protected:
  ~CurrentDependentVoltage() = default;
};

/// A stretch of a period with a constant stator voltage (a switch state of the inverter).
struct VoltageSegment {
  double duration_s = 0.0;
  Vec2 u_alphabeta_V = Vec2::Zero();
};

struct PlantConfig {
  double period_s = 1e-4;  ///< one call of a step function advances this much
  int rk4_substeps = 10;   ///< RK4 steps per period
  /// rk6: the sixth-order steps of plant_integrator.hpp where the right-hand side is smooth
  /// (RK4 with rk4_substeps elsewhere).
  PlantIntegrator integrator = PlantIntegrator::rk4;
};

class InductionMotorPlant {
 public:
  /// Packed state for the integrator: (Phi_a, Phi_b, I_a, I_b, w, th).
  using StateVector = Eigen::Matrix<double, 6, 1>;

  /// Requires valid motor parameters, period_s > 0 and rk4_substeps >= 1.
  InductionMotorPlant(const control::MotorParameters& motor, const PlantConfig& config);

  const PlantState& state() const noexcept { return state_; }
  void set_state(const PlantState& state) noexcept { state_ = state; }
  double time_s() const noexcept { return time_s_; }
  const PlantConfig& config() const noexcept { return config_; }
  int pole_pairs() const noexcept { return motor_.pole_pairs; }
  const control::MotorParameters& motor() const noexcept { return motor_; }
  /// Changes the winding resistances from now on (a stator or rotor heating up); the state
  /// carries over. Both must be > 0.
  void set_resistances(double Rs_Ohm, double Rr_Ohm) noexcept;

  /// Opens phases from now on. With one phase open and the star point floating, the open
  /// terminal's potential is free, and a change of it moves the phase-to-neutral voltages along
  /// that phase's axis only (by 2/3, -1/3, -1/3 of it). It takes whatever value keeps the phase
  /// current at zero, so the constrained model is (1) with the axis component removed from the
  /// stator current (here, once) and from dI/dt (in every later voltage-fed and analog-feedback
  /// step). With two or three phases open no current can flow: it is zeroed, and so is dI/dt.
  /// The current-fed step ignores open phases. `mask`: bit k for phase k open; 0 reconnects all.
  void set_open_phases(unsigned mask) noexcept;
  unsigned open_phases() const noexcept { return open_phases_; }
  /// Exactly this phase open (0..2), or none with nullopt.
  void set_open_phase(std::optional<int> phase) noexcept {
    set_open_phases(phase ? 1u << *phase : 0u);
  }

  /// A holding brake's torque on the shaft: 0 released, T_b engaged. It opposes the motion up
  /// to T_b, and holds the rotor against any smaller torque. Modelled as friction that is
  /// viscous below w_eps = T_b h / J (h the RK4 step): stiff enough that a held rotor creeps at
  /// most at (torque / T_b) w_eps, mild enough for the step (T_b h / (J w_eps) = 1).
  void set_brake_torque(double holding_Nm) noexcept { brake_Nm_ = holding_Nm; }
  double brake_torque() const noexcept { return brake_Nm_; }

  /// One period with the stator voltage u held (stationary frame).
  void step_voltage(const Vec2& u_s_alphabeta_V, double load_Nm) noexcept;
  /// One period with u held plus `error` of the instantaneous stator current.
  void step_voltage(const Vec2& u_s_alphabeta_V, const CurrentDependentVoltage& error,
                    double load_Nm) noexcept;

  /// One period as `count` segments of constant voltage (durations summing to the period),
  /// each integrated with RK4 steps of at most period / rk4_substeps. Records the current's
  /// ripple within the period (period_ripple_sq_A2).
  void step_voltage_segments(const VoltageSegment* segments, std::size_t count,
                             double load_Nm) noexcept;
  /// Over the last step_voltage_segments period: the mean of |I(t) - I_mean|^2 (alpha-beta, the
  /// current linear between integration steps); its half is the mean square per phase.
  double period_ripple_sq_A2() const noexcept { return period_ripple_sq_A2_; }

  /// One period under the ideal analog inner feedback (2) of paper 000:
  /// u(t) = sigma p w J (I + beta Phi) + e^{p th(t) J} v~_k, evaluated at every RK4 stage.
  /// v~_k = e^{-p th_k J} v_k is the held rotor-frame input.
  void step_analog_feedback(const Vec2& v_AB_V, double load_Nm) noexcept;
  /// The stator voltage (2) applies in the present state for the rotor-frame input v~.
  Vec2 analog_feedback_voltage_V(const Vec2& v_AB_V) const noexcept;

  /// One period current-fed: I(t) = e^{p th(t) J} i_AB with i_AB held (paper 001's zero-order
  /// hold in the rotor frame). On return the stator current is that of the end of the period.
  void step_current_fed(const Vec2& i_s_AB_A, double load_Nm) noexcept;

  /// Electromagnetic torque 3/2 p (Lm/Lr) I^T J Phi of the present state.
  double torque_Nm() const noexcept { return torque_Nm(state_); }
  double torque_Nm(const PlantState& state) const noexcept;
  /// 3/2 p (Lm/Lr) I^T J Phi for a current and rotor flux in the same frame.
  double torque_Nm(const Vec2& i_s_A, const Vec2& flux_r_Wb) const noexcept;

  /// Stator flux sigma I + (Lm/Lr) Phi of the present state (stationary frame), or with the
  /// present rotor flux and another stator current (a current-fed step).
  Vec2 flux_s_alphabeta_Wb() const noexcept { return flux_s_alphabeta_Wb(state_.i_s_alphabeta_A); }
  Vec2 flux_s_alphabeta_Wb(const Vec2& i_s_alphabeta_A) const noexcept;

  /// dx/dt of model (1) for stator voltage u and load torque (with open phases, constrained as
  /// set_open_phases describes). Exposed for benchmarks.
  StateVector voltage_fed_derivative(const StateVector& x, const Vec2& u_s_alphabeta_V,
                                     double load_Nm) const noexcept;

 private:
  /// `smooth`: the voltage law is smooth in the state, so the sixth-order method may run it.
  template <bool smooth, typename VoltageLaw>
  void integrate_voltage_fed(const VoltageLaw& voltage_of_state, double load_Nm) noexcept;
  /// The state after one period of dx/dt = rhs(x) from x: RK4 with rk4_substeps, or with
  /// `smooth` and the rk6 integrator (no brake engaged) the sixth-order steps.
  template <bool smooth, typename Rhs>
  StateVector integrate_period(const StateVector& x, const Rhs& rhs) const noexcept;
  /// A stator current (or its derivative) under the open phases' constraint: as is with none
  /// open, without the open axis' component with one, zero with more.
  Vec2 constrained(const Vec2& current) const noexcept;
  /// The shaft's torques besides the motor's at speed w: friction, load and the brake.
  double shaft_torque_Nm(double omega_rad_s, double load_Nm) const noexcept;

  control::MotorParameters motor_;
  control::VoltageFedConstantsIn<double> k_;  ///< in double whatever the designs' arithmetic
  // 1/sigma and 1/J: the right-hand side, evaluated up to 14 times a period, multiplies by
  // them (neither depends on the resistances, which set_resistances changes).
  double per_sigma_H_, per_J_kgm2_;
  PlantConfig config_;
  PlantState state_;
  double time_s_ = 0.0;
  double period_ripple_sq_A2_ = 0.0;
  unsigned open_phases_ = 0;
  double brake_Nm_ = 0.0;
  Vec2 open_axis_ = Vec2::Zero();  ///< axis of the open phase when exactly one is open
};

}  // namespace imd::sim
