#pragma once
/// The discrete sliding-mode law of paper 000 (control/dsmc.hpp) as the drive's law: speed and
/// squared rotor flux, on the state predicted over the latency, within the feasible inputs.
#include <algorithm>
#include <cmath>
#include <limits>

#include "control/dsmc.hpp"
#include "control/field_weakening.hpp"
#include "control/ifoc_design.hpp"
#include "control/real.hpp"
#include "firmware/drive_config.hpp"
#include "firmware/laws/control_law.hpp"
#include "firmware/laws/law_context.hpp"

namespace imd::firmware {

template <typename T>
class DsmcLaw final : public ControlLaw<T> {
 public:
  static constexpr ControllerKind kKind = ControllerKind::dsmc;

  explicit DsmcLaw(const LawContext& c) noexcept
      : dsmc_(c.coefficients, dsmc_config(c)),
        fw_motor_{T(c.motor.Rs_Ohm), T(c.motor.Ls_H),
                  T(c.motor.Ls_H - c.motor.Lm_H * c.motor.Lm_H / c.motor.Lr_H), T(c.motor.Lm_H)},
        p_(T(c.motor.pole_pairs)),
        slip_per_A_(T(c.motor.Rr_Ohm / c.motor.Lr_H * c.motor.Lm_H)),
        min_flux2_(T(c.config.min_flux2_Wb2)),
        flux2_rise_per_tick_(T(2 * c.config.sample_period_s * c.motor.Rr_Ohm / c.motor.Lr_H)) {}

  /// The law's settings: the paper's speed channel with its reaching pole, or the torque
  /// channel with the pole of its speed bandwidth (docs/control.md). Construction only.
  static control::DsmcConfig dsmc_config(const LawContext& c) noexcept {
    control::DsmcConfig d;
    d.min_flux2_Wb2 = c.config.min_flux2_Wb2;
    d.flux_reaching_pole = c.config.flux_reaching_pole;
    if (c.config.dsmc_paper_speed_channel) {
      d.speed_channel = control::DsmcSpeedChannel::paper;
      d.speed_reaching_pole = c.config.speed_reaching_pole;
      return d;
    }
    d.speed_channel = control::DsmcSpeedChannel::torque;
    const Real speed_bandwidth_rad_s = dsmc_speed_bandwidth_rad_s(c.config);
    d.speed_reaching_pole = std::exp(-speed_bandwidth_rad_s * c.config.sample_period_s);
    // The flux loop a decade below the current's, as the speed loop's first bound: the load
    // steps' cross-coupling is then corrected within a few milliseconds (the current disk
    // bounds what a flux step asks of the d current).
    const Real flux_bandwidth_rad_s = current_bandwidth_rad_s(c.config) / 10;
    d.flux_reaching_pole = std::exp(-flux_bandwidth_rad_s * c.config.sample_period_s);
    // The current approaches its target at the IFOC's current bandwidth, f_s / 20 in rad/s
    // (control/ifoc_design.hpp): pole e^{-pi/10} = 0.73 at any sample rate.
    d.current_pole = std::exp(-current_bandwidth_rad_s(c.config) * c.config.sample_period_s);
    const Real torque_per_product =
        control::kClarkeTorqueFactor * Real(c.motor.pole_pairs) * c.motor.Lm_H / c.motor.Lr_H;
    d.torque_product_limit_AWb = c.config.torque_limit_Nm / torque_per_product;
    return d;
  }
  /// The torque channel's speed bandwidth: the configured one, or the IFOC's rule
  /// min(w_c / 10, w_obs / 4) with w_c = 2 pi f_s / 20 (control/ifoc_design.hpp): a decade below
  /// what a current loop at this sample rate reaches, and a factor 4 below the speed estimate's
  /// bandwidth.
  static Real dsmc_speed_bandwidth_rad_s(const DriveConfig& config) noexcept {
    if (config.dsmc_speed_bandwidth_rad_s > 0) return config.dsmc_speed_bandwidth_rad_s;
    return control::default_speed_bandwidth_rad_s(current_bandwidth_rad_s(config),
                                                  config.encoder_observer_bandwidth_rad_s);
  }
  static Real current_bandwidth_rad_s(const DriveConfig& config) noexcept {
    return control::default_current_bandwidth_rad_s(config.sample_period_s);
  }

  /// Takes over the field-weakening limit of the law it replaces.
  void continue_from(const DsmcLaw& old) noexcept {
    flux2_limit_Wb2_ = old.flux2_limit_Wb2_;
    limit_updated_ = old.limit_updated_;
  }
  void start(const control::RotorFrameState<T>& x,
             const control::Vec2<T>& i_AB_A) noexcept override {
    (void)x;
    (void)i_AB_A;
    flux2_limit_Wb2_ = std::numeric_limits<T>::infinity();
    limit_updated_ = false;
  }

  ControlledFlux controlled_flux() const noexcept override { return ControlledFlux::rotor; }
  bool follows_speed() const noexcept override { return true; }

  /// Field weakening: above base speed the squared-flux reference falls to what the voltage
  /// allows in steady state with the torque current flowing, never below the flux of the most
  /// torque per volt (control/field_weakening.hpp, the IFOC's rule), with a tenth of the disk
  /// left to the transients. The drive updates it after the PWM write on this tick's state, for
  /// the next tick: a limit one period (0.1 ms) late on a speed and a torque current that move
  /// over milliseconds, and the disk bounds each tick's voltage anyway. A step that finds it
  /// not updated since the last step (the first one) computes it itself.
  void after_write(const control::RotorFrameState<T>& x_input, T v_max_V) noexcept override {
    update_field_weakening(x_input, v_max_V);
  }

  LawOutput<T> step(const LawInput<T>& in, LawDiagnostics<T>& report) noexcept override {
    if (!limit_updated_) update_field_weakening(in.e.x_input, in.v_max_V);
    limit_updated_ = false;
    const T flux2_limit = flux2_limit_Wb2_;

    control::DsmcInput<T> d;
    d.flux_r_AB_Wb = in.e.x_input.flux_r_AB_Wb;
    d.i_s_AB_A = in.e.x_input.i_s_AB_A;
    d.omega_mech_rad_s = in.e.x_input.omega_mech_rad_s;
    d.load_Nm = in.e.load_Nm;
    d.omega_ref_rad_s = in.now.omega_mech_rad_s;
    d.omega_ref_next_rad_s = in.next.omega_mech_rad_s;
    d.flux2_ref_Wb2 = std::min(in.now.flux2_Wb2, flux2_limit);
    d.flux2_ref_next_Wb2 = std::min(in.next.flux2_Wb2, flux2_limit);
    d.feasible = in.feasible;
    const control::DsmcOutput<T> out = dsmc_.step(d);
    report.discriminant = out.discriminant;
    report.c_k = out.c_k;
    report.det_B = out.det_B;
    report.speed_saturated = out.speed_saturated;
    report.flux_saturated = out.flux_saturated;
    report.limit = out.speed_saturated || out.flux_saturated ? Limitation::input
                   : out.torque_clamped                     ? Limitation::torque
                                                            : Limitation::none;
    LawOutput<T> result;
    result.v_AB_V = out.v_AB_V;
    result.ok = out.status == control::DsmcStatus::ok;
    return result;
  }

 private:
  void update_field_weakening(const control::RotorFrameState<T>& x_input, T v_max_V) noexcept {
    const control::Vec2<T>& flux_AB = x_input.flux_r_AB_Wb;
    const T per_flux = T(1) / std::max(flux_AB.norm(), min_flux_Wb_);  // one division
    const T i_q =
        (flux_AB.x() * x_input.i_s_AB_A.y() - flux_AB.y() * x_input.i_s_AB_A.x()) * per_flux;
    const T omega_e = p_ * x_input.omega_mech_rad_s + slip_per_A_ * i_q * per_flux;
    const T v_fw = T(control::kFieldWeakeningVoltageShare) * v_max_V;
    const T flux_limit =
        std::max(control::voltage_limited_flux_Wb(fw_motor_, omega_e, i_q, v_fw),
                 control::max_torque_per_volt_flux_Wb(fw_motor_, omega_e, v_fw));
    // The limit falls at once, and rises no faster than the rotor flux can follow, twice the
    // rotor's rate: at the end of a ramp the torque current drops and the limit jumps up, and
    // a flux reference that jumped with it would take the whole voltage for the flux and turn
    // the torque round (the flux channel has priority on the disk).
    const T allowed = std::max(flux2_limit_Wb2_, min_flux2_) * (T(1) + flux2_rise_per_tick_);
    flux2_limit_Wb2_ = std::min(std::max(flux_limit * flux_limit, min_flux2_), allowed);
    limit_updated_ = true;
  }

  control::Dsmc<T> dsmc_;
  control::FieldWeakeningMotor<T> fw_motor_;
  T p_, slip_per_A_, min_flux2_;
  T flux2_rise_per_tick_;  ///< 2 delta / tau_r
  T min_flux_Wb_ = std::sqrt(min_flux2_);  ///< once, not per tick (after min_flux2_)
  T flux2_limit_Wb2_ = std::numeric_limits<T>::infinity();  ///< field weakening's, next tick
  bool limit_updated_ = false;  ///< since the last step
};

}  // namespace imd::firmware
