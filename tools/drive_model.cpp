// drive_model: prints the exact discretizations of both papers for a motor file, as JSON.
//
//   drive_model discretize --motor FILE.toml [--sample-period-s S] [--control-period-s T0]
//
// Exit codes: 0 success, 2 bad input (command line, motor file).
#include <imd_version.hpp>
#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>

#include <cmath>
#include <cstdlib>
#include <iostream>
#include <string>

#include "control/voltage_fed_model.hpp"
#include "control/current_fed_model.hpp"
#include "hal_sim/config_error.hpp"
#include "hal_sim/motor_file.hpp"

namespace {

using imd::control::MotorParameters;
using nlohmann::ordered_json;

constexpr int kExitBadInput = 2;

ordered_json motor_json(const MotorParameters& m) {
  return {{"Rs_Ohm", m.Rs_Ohm},
          {"Ls_H", m.Ls_H},
          {"Lm_H", m.Lm_H},
          {"Rr_Ohm", m.Rr_Ohm},
          {"Lr_H", m.Lr_H},
          {"J_kgm2", m.J_kgm2},
          {"pole_pairs", m.pole_pairs},
          {"friction_Nms", m.friction_Nms}};
}

ordered_json voltage_fed_json(const MotorParameters& m, double delta_s) {
  const auto k = imd::control::derive_voltage_fed(m);
  const auto c = imd::control::discretize_voltage_fed(m, delta_s);
  return {{"sample_period_s", c.delta_s},
          {"sigma_H", k.sigma_H},
          {"alpha_per_s", k.alpha_per_s},
          {"beta_per_H", k.beta_per_H},
          {"gamma_per_s", k.gamma_per_s},
          {"mu_per_kgm2", k.mu_per_kgm2},
          {"a11", c.a11},
          {"a12", c.a12},
          {"a21", c.a21},
          {"a22", c.a22},
          {"b1", c.b1},
          {"b2", c.b2},
          {"eta1", c.eta1},
          {"eta2", c.eta2},
          {"eta3", c.eta3},
          {"kappa1", c.kappa1},
          {"kappa2", c.kappa2},
          {"kappa3", c.kappa3},
          {"omega_decay", c.omega_decay},
          {"omega_to_theta_s", c.omega_to_theta_s},
          {"load_to_omega", c.load_to_omega},
          {"load_to_theta", c.load_to_theta}};
}

ordered_json current_fed_json(const MotorParameters& m, double T0_s) {
  const auto k = imd::control::derive_current_fed(m);
  const auto c = imd::control::discretize_current_fed(m, T0_s);
  return {{"control_period_s", c.T0_s},
          {"sigma", k.sigma},
          {"eta_per_s", k.eta_per_s},
          {"zeta_per_H_s", k.zeta_per_H_s},
          {"gamma_per_s", k.gamma_per_s},
          {"flux_decay", c.flux_decay},
          {"flux_from_i_now_H", c.flux_from_i_now_H},
          {"flux_from_i_next_H", c.flux_from_i_next_H},
          {"torque_per_flux_A", c.torque_per_flux_A},
          {"speed_decay", c.speed_decay},
          {"torque_to_speed", c.torque_to_speed},
          {"load_to_speed", c.load_to_speed}};
}

/// A period must be a finite number in (0, 1] s; CLI11's PositiveNumber lets NaN through.
const CLI::Validator kPeriod(
    [](std::string& text) -> std::string {
      char* end = nullptr;
      const double value = std::strtod(text.c_str(), &end);
      if (end == text.c_str() || *end != '\0') return "must be a number, got " + text;
      if (!std::isfinite(value) || value <= 0.0 || value > 1.0) {
        return "must be a period in (0, 1] s, got " + text;
      }
      return {};
    },
    "PERIOD_S");

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"Exact discretizations of the induction-motor models of both papers."};
  app.set_version_flag("--version", imd::version::kText);
  app.require_subcommand(1);
  std::string motor_path;
  double delta_s = 1e-4;
  double T0_s = 1e-3;
  CLI::App* discretize = app.add_subcommand(
      "discretize", "Print the voltage-fed (paper 000) and current-fed (paper 001) coefficients as JSON");
  discretize->add_option("--motor", motor_path, "Motor file (TOML with a [motor] table)")
      ->required();
  discretize->add_option("--sample-period-s", delta_s, "Sample period delta of the paper-000 model")
      ->check(kPeriod)
      ->capture_default_str();
  discretize->add_option("--control-period-s", T0_s, "Control period T0 of the paper-001 model")
      ->check(kPeriod)
      ->capture_default_str();

  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& error) {
    const int code = app.exit(error);
    return code == 0 ? 0 : kExitBadInput;
  }

  try {
    const MotorParameters motor = imd::sim::load_motor_file(motor_path);
    const ordered_json out = {{"motor_file", motor_path},
                              {"motor", motor_json(motor)},
                              {"voltage_fed", voltage_fed_json(motor, delta_s)},
                              {"current_fed", current_fed_json(motor, T0_s)}};
    std::cout << out.dump(2) << '\n';
  } catch (const imd::sim::ConfigError& error) {
    std::cerr << "drive_model: " << error.what() << '\n';
    return kExitBadInput;
  }
  return 0;
}
