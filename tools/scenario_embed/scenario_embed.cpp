// scenario_embed: writes a scenario file as C++ source, for an image without a file system
// (the processor-in-the-loop run on the MCU). The scenario is loaded and mapped to the drive's
// and the board's configuration by the same code drive_sim uses, and every field is written
// with 17 significant digits, so the image runs exactly what drive_sim runs.
//   scenario_embed SCENARIO --name NAME --symbol kName --output FILE.cpp
// Exit codes: 0, 2 (bad input: the loader's message naming the key).
#include <imd_version.hpp>
#include <fmt/format.h>

#include <CLI/CLI.hpp>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <string>

#include "firmware/protocol/messages.hpp"
#include "hal_sim/drive/scenario_config.hpp"
#include "hal_sim/config_error.hpp"
#include "hal_sim/scenario.hpp"
#include "hal_sim/sim_board.hpp"

namespace {

using imd::firmware::ControllerKind;
using imd::firmware::DriveConfig;

// A new field must be written here too: these sizes fail the build until it is.
static_assert(sizeof(DriveConfig) == 472, "DriveConfig changed: write its new fields below");
static_assert(sizeof(imd::sim::SimBoardConfig) == 184, "SimBoardConfig changed: write it below");
static_assert(sizeof(imd::control::MotorParameters) == 64, "MotorParameters changed");

class Writer {
 public:
  explicit Writer(std::string& out) : out_(out) {}
  void number(const std::string& name, double value) {
    std::string text;
    if (std::isnan(value)) {
      text = "std::numeric_limits<double>::quiet_NaN()";
    } else if (std::isinf(value)) {
      text = value > 0 ? "std::numeric_limits<double>::infinity()"
                       : "-std::numeric_limits<double>::infinity()";
    } else {
      text = fmt::format("{:.17g}", value);
    }
    line(name, text);
  }
  void integer(const std::string& name, long long value) { line(name, std::to_string(value)); }
  void boolean(const std::string& name, bool value) { line(name, value ? "true" : "false"); }
  void line(const std::string& name, const std::string& value) {
    out_ += fmt::format("  s.{} = {};\n", name, value);
  }

 private:
  std::string& out_;
};

void write_load(Writer& w, const std::string& p, const imd::sim::LoadProfile& l) {
  using Kind = imd::sim::LoadProfile::Kind;
  w.line(p + ".kind", l.kind == Kind::constant ? "sim::LoadProfile::Kind::constant"
                      : l.kind == Kind::square ? "sim::LoadProfile::Kind::square"
                                               : "sim::LoadProfile::Kind::steps");
  w.number(p + ".value_Nm", l.value_Nm);
  w.number(p + ".low_Nm", l.low_Nm);
  w.number(p + ".high_Nm", l.high_Nm);
  w.number(p + ".period_s", l.period_s);
  w.integer(p + ".step_count", static_cast<long long>(l.step_count));
  for (std::size_t i = 0; i < l.step_count; ++i) {
    w.number(fmt::format("{}.times_s[{}]", p, i), l.times_s[i]);
    w.number(fmt::format("{}.values_Nm[{}]", p, i), l.values_Nm[i]);
  }
}

void write_speed(Writer& w, const std::string& p, const imd::sim::SpeedProfile& v) {
  using Kind = imd::sim::SpeedProfile::Kind;
  w.line(p + ".kind", v.kind == Kind::sine ? "sim::SpeedProfile::Kind::sine"
                                           : "sim::SpeedProfile::Kind::steps");
  w.number(p + ".amplitude_rad_s", v.amplitude_rad_s);
  w.number(p + ".frequency_Hz", v.frequency_Hz);
  w.number(p + ".offset_rad_s", v.offset_rad_s);
  w.integer(p + ".step_count", static_cast<long long>(v.step_count));
  for (std::size_t i = 0; i < v.step_count; ++i) {
    w.number(fmt::format("{}.times_s[{}]", p, i), v.times_s[i]);
    w.number(fmt::format("{}.values_rad_s[{}]", p, i), v.values_rad_s[i]);
  }
}

void write_motor(Writer& w, const std::string& p, const imd::control::MotorParameters& m) {
  w.number(p + ".Rs_Ohm", m.Rs_Ohm);
  w.number(p + ".Ls_H", m.Ls_H);
  w.number(p + ".Lm_H", m.Lm_H);
  w.number(p + ".Rr_Ohm", m.Rr_Ohm);
  w.number(p + ".Lr_H", m.Lr_H);
  w.number(p + ".J_kgm2", m.J_kgm2);
  w.integer(p + ".pole_pairs", m.pole_pairs);
  w.number(p + ".friction_Nms", m.friction_Nms);
}

void write_board(Writer& w, const imd::sim::SimBoardConfig& b) {
  w.number("board.period_s", b.period_s);
  w.integer("board.substeps", b.substeps);
  w.line("board.integrator", b.integrator == imd::sim::PlantIntegrator::rk6
                                 ? "sim::PlantIntegrator::rk6"
                                 : "sim::PlantIntegrator::rk4");
  w.integer("board.pwm_latency_ticks", b.pwm_latency_ticks);
  w.line("board.inner_feedback", b.inner_feedback == imd::sim::InnerFeedback::digital
                                     ? "sim::InnerFeedback::digital"
                                     : "sim::InnerFeedback::ideal_analog");
  w.boolean("board.current_source", b.current_source);
  w.number("board.v_bus_V", b.v_bus_V);
  w.number("board.inverter.dead_time_s", b.inverter.dead_time_s);
  w.number("board.inverter.device_drop_V", b.inverter.device_drop_V);
  w.integer("board.encoder_cpr", b.encoder_cpr);
  w.integer("board.adc.bits", b.adc.bits);
  w.number("board.adc.full_scale_A", b.adc.full_scale_A);
  w.number("board.adc.noise_A", b.adc.noise_A);
  for (int i = 0; i < 3; ++i) w.number(fmt::format("board.adc.offset_A[{}]", i), b.adc.offset_A[i]);
  w.number("board.adc.bus_full_scale_V", b.adc.bus_full_scale_V);
  w.number("board.adc.bus_noise_V", b.adc.bus_noise_V);
  w.line("board.seed", fmt::format("{}u", b.seed));
  w.number("board.drift.Rs_scale_end", b.drift.Rs_scale_end);
  w.number("board.drift.Rr_scale_end", b.drift.Rr_scale_end);
  w.number("board.drift.duration_s", b.drift.duration_s);
  w.boolean("board.switching_inverter", b.switching_inverter);
  w.number("board.brake.holding_torque_Nm", b.brake.holding_torque_Nm);
  w.number("board.brake.engage_delay_s", b.brake.engage_delay_s);
  w.number("board.brake.release_delay_s", b.brake.release_delay_s);
}

void write_drive(Writer& w, const DriveConfig& c) {
  w.number("drive.sample_period_s", c.sample_period_s);
  // The enumerators are named as the CAN protocol names the laws.
  w.line("drive.controller",
         fmt::format("ControllerKind::{}",
                     imd::firmware::protocol::kControllerValues[static_cast<int>(c.controller)].name));
  w.integer("drive.pwm_latency_ticks", c.pwm_latency_ticks);
  w.boolean("drive.compensate_latency", c.compensate_latency);
  w.number("drive.iol_period_s", c.iol_period_s);
  w.integer("drive.current_response_ticks", c.current_response_ticks);
  w.boolean("drive.outer_speed_loop", c.outer_speed_loop);
  w.boolean("drive.outer_flux_loop", c.outer_flux_loop);
  w.number("drive.speed_loop_bandwidth_rad_s", c.speed_loop_bandwidth_rad_s);
  w.number("drive.torque_limit_Nm", c.torque_limit_Nm);
  w.number("drive.flux_loop_time_constant_s", c.flux_loop_time_constant_s);
  w.number("drive.ifoc_current_bandwidth_rad_s", c.ifoc_current_bandwidth_rad_s);
  w.number("drive.ifoc_speed_bandwidth_rad_s", c.ifoc_speed_bandwidth_rad_s);
  w.number("drive.max_accel_rad_s2", c.max_accel_rad_s2);
  w.number("drive.speed_reaching_pole", c.speed_reaching_pole);
  w.number("drive.flux_reaching_pole", c.flux_reaching_pole);
  w.boolean("drive.dsmc_paper_speed_channel", c.dsmc_paper_speed_channel);
  w.number("drive.dsmc_speed_bandwidth_rad_s", c.dsmc_speed_bandwidth_rad_s);
  w.boolean("drive.rotor_resistance_tracking", c.rotor_resistance_tracking);
  w.number("drive.rr_convergence_time_constant_s", c.rr_convergence_time_constant_s);
  w.number("drive.rr_retune_share", c.rr_retune_share);
  w.number("drive.rr_retune_interval_s", c.rr_retune_interval_s);
  w.boolean("drive.voltage_limited", c.voltage_limited);
  w.number("drive.modulation_margin", c.modulation_margin);
  w.number("drive.i_max_A", c.i_max_A);
  w.number("drive.current_margin", c.current_margin);
  w.number("drive.dead_time_s", c.dead_time_s);
  w.boolean("drive.compensate_dead_time", c.compensate_dead_time);
  w.integer("drive.adc_calibration_ticks", c.adc_calibration_ticks);
  w.number("drive.adc_offset_limit_A", c.adc_offset_limit_A);
  w.number("drive.magnetizing_current_A", c.magnetizing_current_A);
  w.number("drive.magnetized_fraction", c.magnetized_fraction);
  w.number("drive.magnetizing_timeout_s", c.magnetizing_timeout_s);
  w.number("drive.encoder_observer_bandwidth_rad_s", c.encoder_observer_bandwidth_rad_s);
  w.boolean("drive.section_iv_load_estimator", c.section_iv_load_estimator);
  w.number("drive.load_estimator_pole", c.load_estimator_pole);
  w.number("drive.min_flux2_Wb2", c.min_flux2_Wb2);
  const imd::firmware::ProtectionConfig& p = c.protection;
  w.boolean("drive.protection.check_encoder", p.check_encoder);
  w.boolean("drive.protection.check_adc_stuck", p.check_adc_stuck);
  w.number("drive.protection.overcurrent_A", p.overcurrent_A);
  w.number("drive.protection.bus_min_V", p.bus_min_V);
  w.number("drive.protection.bus_max_V", p.bus_max_V);
  w.number("drive.protection.overspeed_rad_s", p.overspeed_rad_s);
  w.number("drive.protection.encoder_missing_counts", p.encoder_missing_counts);
  w.number("drive.protection.encoder_max_load_share", p.encoder_max_load_share);
  w.integer("drive.protection.adc_stuck_ticks", p.adc_stuck_ticks);
  w.number("drive.protection.inverter_voltage_error_share", p.inverter_voltage_error_share);
  w.number("drive.protection.adc_noise_codes", p.adc_noise_codes);
  w.number("drive.protection.command_timeout_s", p.command_timeout_s);
  w.line("drive.protection.tick_budget_ns", fmt::format("{}u", p.tick_budget_ns));
  const auto stop = [](imd::firmware::StopCategory category) {
    static const char* const kNames[] = {"none", "sto", "ss1", "dc_brake"};
    return std::string("firmware::StopCategory::") + kNames[static_cast<int>(category)];
  };
  w.line("drive.protection.stop.command_timeout", stop(p.stop.command_timeout));
  w.line("drive.protection.stop.emergency_stop", stop(p.stop.emergency_stop));
  w.line("drive.protection.stop.encoder", stop(p.stop.encoder));
  w.number("drive.protection.dc_brake_current_share", p.dc_brake_current_share);
  w.integer("drive.stage_timing_period_ticks", c.stage_timing_period_ticks);
  w.integer("drive.node_id", c.node_id);
  w.boolean("drive.commands_over_can", c.commands_over_can);
  w.boolean("drive.auto_enable", c.auto_enable);
  w.integer("drive.telemetry_rate_Hz", c.telemetry_rate_Hz);
  w.number("drive.min_flux2_command_Wb2", c.min_flux2_command_Wb2);
  w.number("drive.max_flux2_Wb2", c.max_flux2_Wb2);
  w.number("drive.flux2_ref_Wb2", c.flux2_ref_Wb2);
  w.number("drive.stator_flux2_ref_Wb2", c.stator_flux2_ref_Wb2);
  w.integer("drive.enable_input_line", c.enable_input_line);
  w.integer("drive.fault_output_line", c.fault_output_line);
  w.integer("drive.brake_output_line", c.brake_output_line);
  w.number("drive.brake_release_time_s", c.brake_release_time_s);
  w.integer("drive.timing_output_line", c.timing_output_line);
  w.number("drive.stop_decel_rad_s2", c.stop_decel_rad_s2);
  w.number("drive.stop_speed_rad_s", c.stop_speed_rad_s);
  w.number("drive.stop_timeout_s", c.stop_timeout_s);
}

/// The source text; throws ConfigError for a scenario the processor-in-the-loop run cannot
/// reproduce.
std::string embed(const imd::sim::Scenario& s, const std::string& name,
                  const std::string& symbol, const std::string& source_name) {
  auto refuse = [&](const std::string& why) {
    throw imd::sim::ConfigError(fmt::format("{}: {}", source_name, why));
  };
  // What the processor-in-the-loop runner does not do: it measures the DSMC's metrics of a
  // profile run, with the board's own sensors.
  if (s.command_source != "profile") refuse("drive.command_source must be \"profile\"");
  if (s.ideal_sensors) refuse("sensors.ideal must be false (an MCU has no oracle)");
  if (s.inner_feedback != imd::sim::InnerFeedback::digital || s.current_fed) {
    refuse("the inner feedback must be digital (the analog device exists only on the host)");
  }
  if (!s.faults.empty() || !s.can_commands.empty()) refuse("faults and can_commands are not run");

  imd::sim::SimBoard board(s.plant, imd::sim::board_config(s));
  imd::sim::prepare_board(board, s);
  const imd::sim::PlantState& x0 = board.plant().state();

  std::string body;
  Writer w(body);
  w.line("name", fmt::format("\"{}\"", name));
  write_motor(w, "motor", s.motor);
  write_motor(w, "plant", s.plant);
  write_board(w, imd::sim::board_config(s));
  write_drive(w, imd::sim::drive_config(s));
  write_speed(w, "references.speed", s.speed);
  w.number("references.flux2_Wb2", s.flux2_Wb2);
  write_load(w, "references.torque", s.torque);
  w.number("references.stator_flux2_Wb2", s.stator_flux2_Wb2);
  write_load(w, "load", s.load);
  w.number("initial_state.flux_r_alphabeta_Wb.x()", x0.flux_r_alphabeta_Wb.x());
  w.number("initial_state.flux_r_alphabeta_Wb.y()", x0.flux_r_alphabeta_Wb.y());
  w.number("initial_state.i_s_alphabeta_A.x()", x0.i_s_alphabeta_A.x());
  w.number("initial_state.i_s_alphabeta_A.y()", x0.i_s_alphabeta_A.y());
  w.number("initial_state.omega_mech_rad_s", x0.omega_mech_rad_s);
  w.number("initial_state.theta_mech_rad", x0.theta_mech_rad);
  w.number("duration_s", s.duration_s);
  w.number("settle_s", s.settle_s);

  return fmt::format(
      "// Generated by tools/scenario_embed from {}: do not edit.\n"
      "// The unit test scenario_embed_up_to_date regenerates it and fails when it differs.\n"
      "#include <limits>\n\n"
      "#include \"hal_sim/drive/embedded_scenario.hpp\"\n\n"
      "// The values are the file's, in double; the drive's parameters are in its design\n"
      "// arithmetic (float on the MCU: control/real.hpp), each rounded once as assigned.\n"
      "#pragma GCC diagnostic ignored \"-Wfloat-conversion\"\n\n"
      "namespace imd::firmware {{\n\n"
      "extern const sim::EmbeddedScenario {};\n"
      "const sim::EmbeddedScenario {} = [] {{\n"
      "  sim::EmbeddedScenario s;\n{}  return s;\n}}();\n\n"
      "}}  // namespace imd::firmware\n",
      source_name, symbol, symbol, body);
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"Writes a scenario file as C++ source for an image without a file system."};
  app.set_version_flag("--version", imd::version::kText);
  std::string scenario_path, name, symbol, output;
  app.add_option("scenario", scenario_path, "Scenario file (TOML)")->required();
  app.add_option("--name", name, "Name the image prints, e.g. seed000_realistic")->required();
  app.add_option("--symbol", symbol, "C++ name of the EmbeddedScenario, e.g. kSeed000Realistic")
      ->required();
  app.add_option("--output", output, "The .cpp file to write")->required();
  CLI11_PARSE(app, argc, argv);
  try {
    const imd::sim::Scenario s = imd::sim::load_scenario(scenario_path);
    // The file's name as the repository spells it, whatever the caller's directory.
    const std::string source_name =
        std::filesystem::path(scenario_path).parent_path().parent_path().filename().string() +
        "/" + std::filesystem::path(scenario_path).parent_path().filename().string() + "/" +
        std::filesystem::path(scenario_path).filename().string();
    const std::string text = embed(s, name, symbol, source_name);
    std::ofstream file(output);
    if (!(file << text)) {
      std::cerr << "scenario_embed: " << output << ": cannot write\n";
      return 2;
    }
  } catch (const imd::sim::ConfigError& e) {
    std::cerr << "scenario_embed: " << e.what() << "\n";
    return 2;
  }
  return 0;
}
