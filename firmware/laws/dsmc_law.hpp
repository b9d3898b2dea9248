#pragma once
/// The discrete sliding-mode law of paper 000 (control/dsmc.hpp) as the drive's law: speed and
/// squared rotor flux, on the state predicted over the latency, within the feasible inputs.
#include "control/dsmc.hpp"
#include "firmware/drive_config.hpp"
#include "firmware/laws/control_law.hpp"
#include "firmware/laws/law_context.hpp"

namespace imd::firmware {

template <typename T>
class DsmcLaw final : public ControlLaw<T> {
 public:
  static constexpr ControllerKind kKind = ControllerKind::dsmc;

  explicit DsmcLaw(const LawContext& c) noexcept
      : dsmc_(c.coefficients,
              control::DsmcConfig{c.config.min_flux2_Wb2, c.config.speed_reaching_pole,
                                  c.config.flux_reaching_pole}) {}

  /// The law keeps no state from tick to tick: nothing to take over from the one it replaces.
  void continue_from(const DsmcLaw& old) noexcept { (void)old; }

  ControlledFlux controlled_flux() const noexcept override { return ControlledFlux::rotor; }
  bool follows_speed() const noexcept override { return true; }

  LawOutput<T> step(const LawInput<T>& in, LawDiagnostics<T>& report) noexcept override {
    control::DsmcInput<T> d;
    d.flux_r_AB_Wb = in.e.x_input.flux_r_AB_Wb;
    d.i_s_AB_A = in.e.x_input.i_s_AB_A;
    d.omega_mech_rad_s = in.e.x_input.omega_mech_rad_s;
    d.load_Nm = in.e.load_Nm;
    d.omega_ref_rad_s = in.now.omega_mech_rad_s;
    d.omega_ref_next_rad_s = in.next.omega_mech_rad_s;
    d.flux2_ref_Wb2 = in.now.flux2_Wb2;
    d.flux2_ref_next_Wb2 = in.next.flux2_Wb2;
    d.feasible = in.feasible;
    const control::DsmcOutput<T> out = dsmc_.step(d);
    report.discriminant = out.discriminant;
    report.c_k = out.c_k;
    report.det_B = out.det_B;
    report.speed_saturated = out.speed_saturated;
    report.flux_saturated = out.flux_saturated;
    LawOutput<T> result;
    result.v_AB_V = out.v_AB_V;
    result.ok = out.status == control::DsmcStatus::ok;
    return result;
  }

 private:
  control::Dsmc<T> dsmc_;
};

}  // namespace imd::firmware
