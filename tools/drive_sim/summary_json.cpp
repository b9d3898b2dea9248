// drive_sim's summary JSON (tools/drive_sim/summary_json.hpp).
#include "tools/drive_sim/summary_json.hpp"

#include <cmath>
#include <string>

namespace imd::tools {
namespace {

nlohmann::ordered_json motor_json(const imd::control::MotorParameters& m) {
  return {{"Rs_Ohm", m.Rs_Ohm},
          {"Ls_H", m.Ls_H},
          {"Lm_H", m.Lm_H},
          {"Rr_Ohm", m.Rr_Ohm},
          {"Lr_H", m.Lr_H},
          {"J_kgm2", m.J_kgm2},
          {"pole_pairs", m.pole_pairs},
          {"friction_Nms", m.friction_Nms}};
}

/// A commissioning run's report: "identified" (the record's keys, and the quantities the
/// terminals determine) and "identification" (how it ended, the time of each step).
void commissioning_json(const imd::sim::CommissioningReport& c, nlohmann::ordered_json& out) {
  nlohmann::ordered_json steps = nlohmann::ordered_json::object();
  for (const auto& [name, seconds] : c.step_s) steps[name] = seconds;
  out["identification"] = {
      {"ended", c.ended},     {"result", c.step},
      {"failure", c.failure}, {"steps_s", steps},
      {"total_s", c.total_s}, {"mechanics", c.mechanics_measured ? "measured" : "not measured"}};
  if (!c.identified) {
    out["identified"] = nullptr;
    return;
  }
  const imd::control::MotorParameters& m = *c.identified;
  nlohmann::ordered_json identified = motor_json(m);
  identified["sigma_Ls_H"] = m.Ls_H - m.Lm_H * m.Lm_H / m.Lr_H;
  identified["tau_r_s"] = m.Lr_H / m.Rr_Ohm;
  identified["Lm2_over_Lr_H"] = m.Lm_H * m.Lm_H / m.Lr_H;
  out["identified"] = identified;
}

/// A number, or null when it is not defined (NaN).
nlohmann::ordered_json json_number(double value) {
  return std::isfinite(value) ? nlohmann::ordered_json(value) : nlohmann::ordered_json(nullptr);
}

/// The last limitation: {reason, from_s, to_s (null: it held to the end)}, or null.
nlohmann::ordered_json limited_json(const imd::sim::Summary& r) {
  if (!r.limited) return nullptr;
  return {{"reason", r.limited->reason},
          {"from_s", r.limited->from_s},
          {"to_s", json_number(r.limited->to_s)}};
}

}  // namespace

nlohmann::ordered_json summary_json(const imd::sim::Scenario& s, const imd::sim::Summary& r) {
  nlohmann::ordered_json faults = nlohmann::ordered_json::array();
  auto time = [](double t_s) {  // NaN: it did not happen
    return std::isfinite(t_s) ? nlohmann::ordered_json(t_s) : nlohmann::ordered_json(nullptr);
  };
  for (const auto& f : r.faults) {
    faults.push_back({{"code", f.code},
                      {"injected", f.injected.empty() ? nlohmann::ordered_json(nullptr)
                                                      : nlohmann::ordered_json(f.injected)},
                      {"injected_at_s", time(f.injected_at_s)},
                      {"detected_at_s", time(f.detected_at_s)},
                      {"pwm_off_at_s", time(f.pwm_off_at_s)},
                      {"detail", f.detail},
                      {"stop", f.stop.empty() ? nlohmann::ordered_json(nullptr)
                                              : nlohmann::ordered_json(f.stop)}});
  }
  nlohmann::ordered_json stages;  // host wall-clock time: for comparison, not the MCU's
  for (int i = 0; i < imd::firmware::kStageCount; ++i) {
    stages[imd::firmware::kStageNames[i]] = r.stage_ns_mean[i];
  }
  nlohmann::ordered_json result = {
      {"scenario", s.source},
      {"controller", s.controller},
      {"precision", s.precision},
      {"motor", motor_json(s.motor)},  // what the controller was given
      {"plant", motor_json(s.plant)},  // what it ran
      {"settle_s", s.settle_s},
      {"speed_rms_err_rad_s", r.speed_rms_err_rad_s},
      {"speed_max_err_rad_s", r.speed_max_err_rad_s},
      {"speed_rms_err_cmd_rad_s", json_number(r.speed_rms_err_cmd_rad_s)},
      {"flux2_rms_err_Wb2", r.flux2_rms_err_Wb2},
      {"flux2_max_err_Wb2", r.flux2_max_err_Wb2},
      {"load_est_rms_err_Nm", r.load_est_rms_err_Nm},
      {"torque_rms_err_Nm", r.torque_rms_err_Nm},
      {"i_hold_rms_err_A", r.i_hold_rms_err_A},
      {"i_peak_A", r.i_peak_A},
      {"rotor_resistance_tracking", r.rr_tracking},
      {"rr_estimate_final_Ohm", json_number(r.rr_estimate_final_Ohm)},
      {"plant_Rr_final_Ohm", json_number(r.plant_Rr_final_Ohm)},
      {"rr_rel_err_max", json_number(r.rr_rel_err_max)},
      {"rr_retunes", r.rr_retunes},
      {"i_peak_total_A", r.i_peak_total_A},
      {"current_ripple_control_rms_A", json_number(r.current_ripple_control_rms_A)},
      {"voltage_ripple_rms_V", json_number(r.voltage_ripple_rms_V)},
      {"current_ripple_rms_A", json_number(r.current_ripple_rms_A)},
      {"i_max_A", std::isfinite(s.i_max_A) ? nlohmann::ordered_json(s.i_max_A)
                                           : nlohmann::ordered_json(nullptr)},
      {"saturated_fraction", r.saturated_fraction},
      {"limited", limited_json(r)},
      {"limited_total_s", r.limited_total_s},
      {"running_from_s", r.running_from_s},
      {"ticks", r.ticks},
      {"simulated_s", r.simulated_s},
      {"wall_time_s", r.wall_time_s},
      {"simulated_s_per_wall_s", r.wall_time_s > 0 ? r.simulated_s / r.wall_time_s : 0.0},
      {"tick_exec_ns_mean", r.tick_exec_ns_mean},
      {"tick_exec_ns_max", r.tick_exec_ns_max},
      {"stage_ns", stages},
      {"faults", faults}};
  if (r.commissioning) commissioning_json(*r.commissioning, result);
  return result;
}

}  // namespace imd::tools
