#pragma once
/// The input-output linearizing law of paper 001 (control/iol.hpp, run every T0 by
/// firmware/laws/iol_stage.hpp) as the drive's law: torque and squared stator flux. Its
/// rotor-frame current commands reach the motor through the deadbeat current loop on the exact
/// voltage-fed model (control/deadbeat_current.hpp).
#include "control/deadbeat_current.hpp"
#include "firmware/drive_config.hpp"
#include "firmware/laws/control_law.hpp"
#include "firmware/laws/iol_stage.hpp"
#include "firmware/laws/law_context.hpp"

namespace imd::firmware {

template <typename T>
class IolLaw final : public ControlLaw<T> {
 public:
  static constexpr ControllerKind kKind = ControllerKind::iol;

  explicit IolLaw(const LawContext& c)
      : stage_(c.motor, c.config, c.coefficients),
        current_loop_(c.coefficients),
        follows_speed_(c.config.outer_speed_loop) {}

  ControlledFlux controlled_flux() const noexcept override { return ControlledFlux::stator; }
  bool follows_speed() const noexcept override { return follows_speed_; }
  uint32_t lookahead_ticks() const noexcept override {
    return static_cast<uint32_t>(stage_.ticks_per_period());
  }
  void start(const control::RotorFrameState<T>& x,
             const control::Vec2<T>& i_AB_A) noexcept override {
    (void)x;
    stage_.start(i_AB_A);
  }

  LawOutput<T> step(const LawInput<T>& in, LawDiagnostics<T>& report) noexcept override {
    const IolTickResult<T> r =
        stage_.tick(in.e.x.flux_r_AB_Wb, in.e.x.omega_mech_rad_s, in.ahead, in.v_max_V,
                    in.e.x.i_s_AB_A);
    LawOutput<T> out;
    out.ok = r.status == control::IolStatus::ok;
    out.i_cmd_AB_A = r.i_cmd_AB_A;
    const control::Vec2<T> wanted =
        current_loop_.wanted(in.e.x_input.flux_r_AB_Wb, in.e.x_input.i_s_AB_A, r.i_cmd_AB_A);
    out.v_AB_V = in.feasible.clamp(wanted);
    report.limit = !in.feasible.contains(wanted) ? Limitation::input
                   : r.torque_held_back         ? Limitation::torque
                                                : Limitation::none;
    report.i_held_AB_A = r.i_held_AB_A;
    report.iol_boundary = r.boundary;
    if (r.boundary) {
      report.torque_ref_Nm = r.torque_ref_Nm;
      report.torque_cmd_Nm = r.torque_cmd_Nm;
      report.y2 = r.y2;
      report.y2_ref = r.y2_ref;
      report.stator_flux2_est_Wb2 = r.flux2_s_Wb2;
      report.torque_limited = r.torque_limited;
    }
    return out;
  }

  /// Takes over the state of the object this one replaces (the same motor but for its
  /// rotor resistance): the tick changes coefficients and keeps state (docs/robustness.md).
  void continue_from(const IolLaw& old) noexcept {
    stage_.continue_from(old.stage_);
  }

 private:
  IolStage<T> stage_;
  control::DeadbeatCurrent<T> current_loop_;
  bool follows_speed_;
};

}  // namespace imd::firmware
