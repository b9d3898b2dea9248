#include "hal_sim/scenario.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <functional>
#include <limits>
#include <set>
#include <sstream>

#include "hal_sim/config_error.hpp"
#include "hal_sim/motor_file.hpp"
#include "hal_sim/scenario_document.hpp"
#include "hal_sim/scenario_reader.hpp"

namespace imd::sim {

namespace {

using detail::KeyOrigins;
using detail::kMotorKeys;
using detail::Reader;

/// [plant] keys that are not the motor's: its resistances' drift over the run.
const std::set<std::string> kDriftKeys = {"Rs_scale_end", "Rr_scale_end"};

/// A steps table: times in increasing order, one value per time, at most N steps (the profiles
/// hold them in fixed storage). Returns the number of steps.
template <std::size_t N>
std::size_t read_steps(Reader& r, std::string_view times_key, std::string_view values_key,
                       std::array<double, N>& times, std::array<double, N>& values) {
  const std::vector<double> read_times = r.numbers(times_key);
  const std::vector<double> read_values = r.numbers(values_key);
  if (read_times.size() != read_values.size()) {
    r.fail(values_key, "must have as many entries as the times");
  }
  if (read_times.size() > N) {
    r.fail(times_key, fmt::format("has {} entries: must have at most {}", read_times.size(), N));
  }
  if (!std::is_sorted(read_times.begin(), read_times.end())) {
    r.fail(times_key, "must be in increasing order");
  }
  std::copy(read_times.begin(), read_times.end(), times.begin());
  std::copy(read_values.begin(), read_values.end(), values.begin());
  return read_times.size();
}

void read_speed_reference(Reader& r, Scenario& s) {
  const std::string kind = r.choice("reference.speed.kind", "", {"sine", "steps"});
  if (kind.empty()) r.fail("reference.speed.kind", "missing key");
  if (kind == "sine") {
    s.speed.kind = SpeedProfile::Kind::sine;
    s.speed.amplitude_rad_s = r.number("reference.speed.amplitude_rad_s", std::nullopt);
    s.speed.frequency_Hz = r.non_negative("reference.speed.frequency_Hz", std::nullopt);
    s.speed.offset_rad_s = r.number("reference.speed.offset_rad_s", 0.0);
  } else {
    s.speed.kind = SpeedProfile::Kind::steps;
    s.speed.step_count = read_steps(r, "reference.speed.times_s", "reference.speed.values_rad_s",
                                    s.speed.times_s, s.speed.values_rad_s);
  }
}

/// A piecewise profile under `prefix`: constant (value_Nm), square (low_Nm, high_Nm, period_s)
/// or steps (times_s, values_Nm).
void read_load_like(Reader& r, const std::string& prefix, LoadProfile& p) {
  const auto key = [&](const char* name) { return prefix + "." + name; };
  const std::string kind = r.choice(key("kind"), "constant", {"constant", "square", "steps"});
  if (kind == "constant") {
    p.kind = LoadProfile::Kind::constant;
    p.value_Nm = r.number(key("value_Nm"), 0.0);
  } else if (kind == "square") {
    p.kind = LoadProfile::Kind::square;
    p.low_Nm = r.number(key("low_Nm"), std::nullopt);
    p.high_Nm = r.number(key("high_Nm"), std::nullopt);
    p.period_s = r.positive(key("period_s"), std::nullopt);
  } else {
    p.kind = LoadProfile::Kind::steps;
    p.step_count = read_steps(r, key("times_s"), key("values_Nm"), p.times_s, p.values_Nm);
  }
}

/// The simulated motor: [plant] motor_file, or else [motor], with the keys [plant] changes (any
/// motor key, nothing else). `base`: the plant's motor when it is not [motor].
control::MotorParameters parse_plant_table(const toml::table& doc, const KeyOrigins& origins,
                                           const std::optional<toml::table>& base) {
  const auto origin_of = [&](const std::string& table) {
    return [&origins, table](std::string_view key) {
      return origins.of(key.empty() ? table : table + "." + std::string(key));
    };
  };
  const toml::node* plant = doc.get("plant");
  if (plant == nullptr && !base) return parse_motor_table(doc, origin_of("motor"));
  if (plant != nullptr && !plant->is_table()) {
    throw ConfigError(fmt::format("{}: plant must be a table", origins.of("plant")));
  }
  toml::table completed = base ? *base : *doc.get("motor")->as_table();  // checked
  const toml::table changes = plant != nullptr ? *plant->as_table() : toml::table{};
  for (auto&& [key, value] : changes) {
    if (kDriftKeys.count(std::string(key.str()))) continue;  // not the motor's: the run's
    if (!kMotorKeys.count(std::string(key.str())) && key.str() != "name") {
      const std::string path = "plant." + std::string(key.str());
      throw ConfigError(
          fmt::format("{}: unknown key {} (a motor key: Rs_Ohm, Ls_H, Lm_H, "
                      "Rr_Ohm, Lr_H, J_kgm2, pole_pairs, friction_Nms; or Rr_scale_end, "
                      "Rs_scale_end)",
                      origins.of(path), path));
    }
    completed.insert_or_assign(key, value);
  }
  toml::table holder;
  holder.insert("plant", std::move(completed));
  return parse_motor_table(holder, origin_of("plant"), "plant");
}

}  // namespace

Scenario load_scenario(const std::filesystem::path& path, const std::vector<std::string>& overrides,
                       const std::optional<std::filesystem::path>& model_file) {
  std::vector<ScenarioOverride> flagged;
  for (const std::string& o : overrides) flagged.push_back({o, "--set " + o});
  return load_scenario_with_flags(path, flagged, model_file);
}

Scenario load_scenario_with_flags(const std::filesystem::path& path,
                                  const std::vector<ScenarioOverride>& overrides,
                                  const std::optional<std::filesystem::path>& model_file) {
  const detail::ScenarioDocument document = detail::assemble_scenario(path, overrides, model_file);
  const toml::table& doc = document.doc;
  const KeyOrigins& origins = document.origins;

  Scenario s;
  s.source = path.string();
  s.motor = parse_motor_table(doc, [&](std::string_view key) {
    return origins.of(key.empty() ? std::string("motor") : "motor." + std::string(key));
  });
  s.plant = parse_plant_table(doc, origins, document.plant_base);
  Reader r(doc, origins);
  r.accept_table("motor");
  r.accept_table("plant");

  s.sample_period_s = r.positive("drive.sample_period_s", 1e-4);
  if (s.sample_period_s < 1e-6 || s.sample_period_s > 1e-2) {
    r.fail("drive.sample_period_s",
           fmt::format("= {}: must be in [1e-6, 1e-2] s", s.sample_period_s));
  }
  s.controller = r.choice("drive.controller", "dsmc", kScenarioControllers);
  const bool iol = s.controller == "iol";
  s.iol_period_s = r.positive("drive.iol_period_s", 1e-3);
  const double ratio = s.iol_period_s / s.sample_period_s;
  if (std::abs(ratio - std::round(ratio)) > 1e-9 * ratio || ratio < 1.0) {
    r.fail_with("drive.iol_period_s", "drive.sample_period_s",
                fmt::format("= {}: must be a whole number of drive.sample_period_s ({})",
                            s.iol_period_s, s.sample_period_s));
  }
  s.outer_speed_loop = r.boolean("drive.outer_speed_loop", false);
  s.outer_flux_loop = r.boolean("drive.outer_flux_loop", false);
  s.speed_loop_bandwidth_rad_s = r.positive("drive.speed_loop_bandwidth_rad_s", 30.0);
  s.torque_limit_Nm = r.positive("drive.torque_limit_Nm", 240.0);
  s.flux_loop_time_constant_s = r.positive("drive.flux_loop_time_constant_s", 0.01);
  s.ifoc_current_bandwidth_rad_s = r.non_negative("drive.ifoc_current_bandwidth_rad_s", 0.0);
  s.ifoc_speed_bandwidth_rad_s = r.non_negative("drive.ifoc_speed_bandwidth_rad_s", 0.0);
  if (s.flux_loop_time_constant_s < 2.0 * s.iol_period_s) {  // keeps Kp below e (docs/iol.md)
    r.fail_with("drive.flux_loop_time_constant_s", "drive.iol_period_s",
                fmt::format("= {}: must be >= 2 drive.iol_period_s ({})",
                            s.flux_loop_time_constant_s, s.iol_period_s));
  }
  s.magnetized_fraction = r.number("drive.magnetized_fraction", 0.95);
  s.magnetizing_current_A = r.non_negative("drive.magnetizing_current_A", 0.0);
  if (!(s.magnetized_fraction > 0.0 && s.magnetized_fraction < 1.0)) {
    r.fail("drive.magnetized_fraction",
           fmt::format("= {}: must be in (0, 1)", s.magnetized_fraction));
  }
  s.precision = r.choice("drive.precision", "double", {"double", "float"});
  s.max_accel_rad_s2 = r.positive_or_inf("drive.max_accel_rad_s2");
  s.compensate_latency = r.boolean("drive.compensate_latency", true);
  s.command_source = r.choice("drive.command_source", "profile", {"profile", "can"});
  for (auto [key, value] : {std::pair{"drive.speed_reaching_pole", &s.speed_reaching_pole},
                            std::pair{"drive.flux_reaching_pole", &s.flux_reaching_pole}}) {
    *value = r.number(key, 0.0);
    if (!(*value >= 0.0 && *value < 1.0))
      r.fail(key, fmt::format("= {}: must be in [0, 1)", *value));
  }

  // The speed reference drives the DSMC and the iol's outer speed loop; the iol without it
  // follows a torque reference.
  // With command_source = "can" it comes only from CAN commands.
  if (r.present("nameplate") && s.command_source != "can") {
    const std::string why =
        "a commissioning run ([nameplate]) needs drive.command_source = \"can\": the nameplate "
        "and the identify command go over CAN";
    // Named at the one the command line added, if one was: that is the user's latest step.
    if (r.from_command_line("nameplate") && !r.from_command_line("drive.command_source")) {
      r.fail_with("nameplate", "drive.command_source", why);
    }
    r.fail_with("drive.command_source", "nameplate", why);
  }
  if (s.command_source == "can") {
    if (r.present("reference.speed")) {
      r.fail_with("reference.speed", "drive.command_source",
                  "must be absent with drive.command_source = \"can\" (CAN commands set the "
                  "speed)");
    }
  } else if (!iol || s.outer_speed_loop || r.find("reference.speed.kind") != nullptr) {
    read_speed_reference(r, s);
  }
  if (iol) {
    s.stator_flux2_Wb2 = r.positive("reference.flux.stator_flux2_Wb2", std::nullopt);
    if (!s.outer_speed_loop) read_load_like(r, "reference.torque", s.torque);
  } else {
    s.flux2_Wb2 = r.positive("reference.flux.flux2_Wb2", std::nullopt);
    if (s.flux2_Wb2 <= 2e-3) {  // the drive refuses B_k below 1e-3 Wb^2 (DriveConfig)
      r.fail("reference.flux.flux2_Wb2", fmt::format("= {}: must be > 0.002 Wb^2", s.flux2_Wb2));
    }
  }
  read_load_like(r, "load", s.load);

  s.ideal_sensors = r.boolean("sensors.ideal", false);
  s.encoder_cpr = static_cast<uint32_t>(r.integer("sensors.encoder_cpr", 8192, 4, 1 << 24));
  s.adc.bits = static_cast<int>(r.integer("sensors.adc_bits", 12, 8, 16));
  s.adc.full_scale_A = r.positive("sensors.adc_full_scale_A", 10.0);
  s.adc.noise_A = r.non_negative("sensors.adc_noise_A", 0.0);
  const double offset_A = r.number("sensors.adc_offset_A", 0.0);
  s.adc.offset_A = {offset_A, -0.5 * offset_A, 0.25 * offset_A};
  s.adc.bus_full_scale_V = r.positive("sensors.adc_bus_full_scale_V", 500.0);
  s.adc.bus_noise_V = r.non_negative("sensors.adc_bus_noise_V", 0.0);

  s.v_bus_V = r.positive("inverter.v_bus_V", 311.0);
  if (s.v_bus_V >= s.adc.bus_full_scale_V) {
    r.fail_with("inverter.v_bus_V", "sensors.adc_bus_full_scale_V",
                fmt::format("= {}: must be below sensors.adc_bus_full_scale_V ({})", s.v_bus_V,
                            s.adc.bus_full_scale_V));
  }
  s.i_max_A = r.positive_or_inf("inverter.i_max_A");
  s.limit_voltage = r.boolean("inverter.limit_voltage", true);
  s.inverter.dead_time_s = r.non_negative("inverter.dead_time_s", 0.0);
  if (s.inverter.dead_time_s >= 0.1 * s.sample_period_s) {  // a 10 % duty loss is no inverter
    r.fail_with("inverter.dead_time_s", "drive.sample_period_s",
                fmt::format("= {}: must be below 0.1 * drive.sample_period_s ({})",
                            s.inverter.dead_time_s, s.sample_period_s));
  }
  s.inverter.device_drop_V = r.non_negative("inverter.device_drop_V", 0.0);
  if (s.inverter.device_drop_V >= 0.1 * s.v_bus_V) {
    r.fail_with("inverter.device_drop_V", "inverter.v_bus_V",
                fmt::format("= {}: must be below 0.1 * inverter.v_bus_V ({})",
                            s.inverter.device_drop_V, s.v_bus_V));
  }
  s.switching_inverter =
      r.choice("inverter.model", "average", {"average", "switching"}) == "switching";
  s.brake.holding_torque_Nm = r.non_negative("brake.holding_torque_Nm", 0.0);
  s.brake.engage_delay_s = r.non_negative("brake.engage_delay_s", s.brake.engage_delay_s);
  s.brake.release_delay_s = r.non_negative("brake.release_delay_s", s.brake.release_delay_s);
  s.dead_time_compensation = r.boolean("drive.dead_time_compensation", true);
  s.dsmc_speed_channel = r.choice("drive.dsmc_speed_channel", "torque", {"torque", "paper"});
  s.dsmc_speed_bandwidth_rad_s = r.number("drive.dsmc_speed_bandwidth_rad_s", 0.0);
  if (s.dsmc_speed_bandwidth_rad_s < 0.0 ||
      s.dsmc_speed_bandwidth_rad_s > 0.5 / s.sample_period_s) {
    r.fail_with("drive.dsmc_speed_bandwidth_rad_s", "drive.sample_period_s",
                fmt::format("= {}: must be in [0, {}] rad/s (0: the rule; at most half the sample "
                            "rate)",
                            s.dsmc_speed_bandwidth_rad_s, 0.5 / s.sample_period_s));
  }
  s.rotor_resistance_tracking = r.boolean("drive.rotor_resistance_tracking", true);
  s.rr_convergence_time_constant_s = r.number("drive.rr_convergence_time_constant_s", 0.0);
  s.rr_retune_share = r.number("drive.rr_retune_share", 0.005);
  if (s.rr_retune_share < 0.0 || s.rr_retune_share > 0.5) {
    r.fail("drive.rr_retune_share", fmt::format("= {}: must be in [0, 0.5]", s.rr_retune_share));
  }
  if (s.rr_convergence_time_constant_s < 0.0 || s.rr_convergence_time_constant_s > 100.0) {
    r.fail("drive.rr_convergence_time_constant_s",
           fmt::format("= {}: must be in [0, 100] s (0: the rule)",
                       s.rr_convergence_time_constant_s));
  }

  s.section_iv = r.boolean("observers.section_iv", false);
  if (s.section_iv && !s.ideal_sensors) {
    r.fail_with("observers.section_iv", "sensors.ideal",
                "needs sensors.ideal = true (the Section IV estimators take the measured speed)");
  }
  s.encoder_bandwidth_rad_s = r.positive("observers.encoder_bandwidth_rad_s", 400.0);
  s.load_estimator_pole = r.number("observers.load_estimator_pole", 0.99);
  if (!(s.load_estimator_pole > 0.0 && s.load_estimator_pole < 1.0)) {
    r.fail("observers.load_estimator_pole",
           fmt::format("= {}: must be in (0, 1)", s.load_estimator_pole));
  }

  s.duration_s = r.positive("simulation.duration_s", 1.0);
  if (s.duration_s > 3600.0)
    r.fail("simulation.duration_s", fmt::format("= {}: must be <= 3600 s", s.duration_s));
  // The windings' drift over the run (a rotor heating up): within what a copper or aluminium
  // winding does between -40 and 200 degC, with room on both sides.
  for (auto [key, scale] : {std::pair{"plant.Rs_scale_end", &s.Rs_scale_end},
                             std::pair{"plant.Rr_scale_end", &s.Rr_scale_end}}) {
    *scale = r.number(key, 1.0);
    if (*scale < 0.2 || *scale > 5.0) r.fail(key, fmt::format("= {}: must be in [0.2, 5]", *scale));
  }
  s.substeps = static_cast<int>(r.integer("simulation.substeps", 10, 1, 10000));
  const std::span<const std::string_view> integrators(kPlantIntegratorNames);
  s.integrator = *integrator_named(r.choice("simulation.integrator", "rk6", integrators));
  s.inner_feedback =
      r.choice("simulation.inner_feedback", "digital", {"digital", "ideal_analog"}) == "digital"
          ? InnerFeedback::digital
          : InnerFeedback::ideal_analog;
  s.pwm_latency_ticks = static_cast<int>(r.integer("simulation.pwm_latency_ticks", 1, 0, 1));
  s.seed = static_cast<uint64_t>(
      r.integer("simulation.seed", 1, 0, std::numeric_limits<int64_t>::max()));
  s.initial_flux2_Wb2 = r.non_negative("simulation.initial_flux2_Wb2", 0.0);
  s.initial_theta_mech_rad = r.number("simulation.initial_theta_mech_rad", 0.0);
  s.current_fed = r.boolean("simulation.current_fed", false);
  if (s.current_fed && (!iol || !s.ideal_sensors)) {
    r.fail_with("simulation.current_fed", iol ? "sensors.ideal" : "drive.controller",
                "needs drive.controller = \"iol\" and sensors.ideal = true");
  }

  s.settle_s = r.non_negative("metrics.settle_s", 0.5);
  if (s.settle_s >= s.duration_s) {
    r.fail_with(
        "metrics.settle_s", "simulation.duration_s",
        fmt::format("= {}: must be below simulation.duration_s ({})", s.settle_s, s.duration_s));
  }

  detail::read_can(r, s);
  detail::read_protection(r, s);
  detail::read_faults(r, s);
  detail::read_can_commands(r, s);
  detail::read_commissioning(r, s);
  r.reject_unknown();
  return s;
}

}  // namespace imd::sim
