#pragma once
/// Indirect field-oriented control (control/ifoc.hpp) as the drive's law: the baseline of every
/// commercial drive. Its gains follow from the motor, the sample period and the encoder
/// observer's bandwidth (control/ifoc_design.hpp, docs/ifoc.md); it respects the same torque
/// limit, current limit and voltage disk as the other laws. It decides the stator voltage; the
/// modulate stage adds the inner feedback (2) to the law's input v~, so the adapter takes that
/// term off again and the stator voltage acts as decided.
#include <algorithm>
#include <cmath>
#include <limits>

#include "control/ifoc.hpp"
#include "control/ifoc_design.hpp"
#include "control/real.hpp"
#include "firmware/drive_config.hpp"
#include "firmware/laws/control_law.hpp"
#include "firmware/laws/law_context.hpp"
#include "firmware/stages/input_limits.hpp"

namespace imd::firmware {

/// The IFOC's design from the drive's configuration.
inline control::IfocSpec ifoc_spec(const DriveConfig& config) noexcept {
  control::IfocSpec s;
  s.sample_period_s = config.sample_period_s;
  s.current_bandwidth_rad_s = config.ifoc_current_bandwidth_rad_s;
  s.speed_bandwidth_rad_s = config.ifoc_speed_bandwidth_rad_s;
  s.speed_feedback_bandwidth_rad_s = config.encoder_observer_bandwidth_rad_s;
  s.torque_limit_Nm = config.torque_limit_Nm;
  s.current_limit_A = std::isfinite(config.i_max_A) ? config.current_margin * config.i_max_A
                                                    : std::numeric_limits<Real>::max();
  s.min_flux_Wb = std::sqrt(config.min_flux2_Wb2);
  s.latency_ticks = config.compensate_latency ? config.pwm_latency_ticks : 0;
  return s;
}

template <typename T>
class IfocLaw final : public ControlLaw<T> {
 public:
  static constexpr ControllerKind kKind = ControllerKind::ifoc;

  explicit IfocLaw(const LawContext& c)
      : ifoc_(control::design_ifoc(c.motor, ifoc_spec(c.config))), feedback_(c.motor) {}

  ControlledFlux controlled_flux() const noexcept override { return ControlledFlux::rotor; }
  bool follows_speed() const noexcept override { return true; }
  void start(const control::RotorFrameState<T>& x,
             const control::Vec2<T>& i_AB_A) noexcept override {
    ifoc_.start(x.flux_r_AB_Wb, i_AB_A);
  }

  LawOutput<T> step(const LawInput<T>& in, LawDiagnostics<T>& report) noexcept override {
    const control::Vec2<T> inner_V = feedback_.compensation_AB_V(in.e.x_input);
    control::IfocInput<T> f;
    f.i_now_AB_A = in.e.x.i_s_AB_A;
    f.i_input_AB_A = in.e.x_input.i_s_AB_A;
    f.omega_mech_rad_s = in.e.x_input.omega_mech_rad_s;
    f.omega_ref_rad_s = in.now.omega_mech_rad_s;
    f.omega_ref_next_rad_s = in.next.omega_mech_rad_s;
    f.flux_ref_Wb = std::sqrt(std::max(in.next.flux2_Wb2, T(0)));
    f.u_feasible_AB_V = {in.feasible.center_V + inner_V, in.feasible.radius_V};
    f.v_max_V = in.v_max_V;
    const control::IfocOutput<T> out = ifoc_.step(f);
    report.torque_ref_Nm = out.torque_ref_Nm;
    report.torque_cmd_Nm = out.torque_cmd_Nm;
    report.torque_limited = out.torque_limited;
    report.flux_ref_Wb = out.flux_ref_Wb;
    report.slip_rad_s = ifoc_.flux_model().slip_rad_s();
    report.voltage_limited = out.voltage_limited;
    // Its disk is the feasible one, inside both the voltage and the current limit: the drive
    // names the one that binds (InputLimits::binding).
    report.limit = out.voltage_limited  ? Limitation::input
                   : out.torque_limited ? Limitation::current
                   : out.torque_clamped ? Limitation::torque
                                        : Limitation::none;
    LawOutput<T> result;
    result.v_AB_V = out.u_AB_V - inner_V;
    result.i_cmd_AB_A = out.i_ref_AB_A;
    return result;
  }

  void after_write(const control::RotorFrameState<T>& x_input, T v_max_V) noexcept override {
    (void)x_input;  // the step kept what its field weakening needs
    (void)v_max_V;
    ifoc_.update_field_weakening();
  }

  /// Takes over the state of the object this one replaces (the same motor but for its
  /// rotor resistance): the tick changes coefficients and keeps state (docs/robustness.md).
  void continue_from(const IfocLaw& old) noexcept {
    ifoc_.continue_from(old.ifoc_);
  }

 private:
  control::Ifoc<T> ifoc_;
  InnerFeedback<T> feedback_;
};

}  // namespace imd::firmware
