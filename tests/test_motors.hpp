#pragma once
// The motors the tests run on: both papers' motors as shipped, and four more from tests/data
// (0.55 to 37 kW, one to four pole pairs).
// Each comes with magnitudes typical of its operation, used to draw random test states. The
// files are read with toml++ here, so that a test of control/ links control/ alone (the
// validated loader is hal_sim's, tested in tests/hal_sim/test_motor_file.cpp).
#include <toml++/toml.h>

#include <stdexcept>
#include <string>
#include <vector>

#include "control/motor_parameters.hpp"

namespace imd::test {

struct TestMotor {
  std::string name;
  control::MotorParameters parameters;
  double flux_Wb;      ///< typical rotor/stator flux magnitude
  double current_A;    ///< typical stator current magnitude
  double voltage_V;    ///< typical magnitude of the rotor-frame input v~
  double speed_rad_s;  ///< typical mechanical speed
  double load_Nm;      ///< typical load torque
};

inline std::string source_path(const std::string& relative) {
  return std::string(IMD_SOURCE_DIR) + "/" + relative;
}

/// The [motor] table of a motor file (every key present: the shipped files are complete).
inline control::MotorParameters read_motor(const std::string& relative) {
  const toml::table file = toml::parse_file(source_path(relative));
  const auto number = [&](const char* key) {
    const auto value = file["motor"][key].value<double>();
    if (!value) throw std::runtime_error(relative + ": motor." + key + " missing");
    return *value;
  };
  control::MotorParameters m;
  m.Rs_Ohm = number("Rs_Ohm");
  m.Ls_H = number("Ls_H");
  m.Lm_H = number("Lm_H");
  m.Rr_Ohm = number("Rr_Ohm");
  m.Lr_H = number("Lr_H");
  m.J_kgm2 = number("J_kgm2");
  m.pole_pairs = static_cast<int>(number("pole_pairs"));
  m.friction_Nms = number("friction_Nms");
  return m;
}

inline std::vector<TestMotor> test_motors() {
  return {
      {"seed000", read_motor("hal_sim/motors/seed000.toml"), 0.5, 3.0, 300.0, 250.0, 1.0},
      {"seed001", read_motor("hal_sim/motors/seed001.toml"), 1.0, 200.0, 300.0, 150.0, 200.0},
      {"small_4pole_750W", read_motor("tests/data/motors/small_4pole_750W.toml"), 0.8, 2.0, 300.0,
       150.0, 4.0},
      {"six_pole_7kW", read_motor("tests/data/motors/six_pole_7kW.toml"), 0.9, 25.0, 300.0, 100.0,
       60.0},
      {"two_pole_550W", read_motor("tests/data/motors/two_pole_550W.toml"), 0.8, 2.0, 300.0, 200.0,
       1.0},
      {"eight_pole_15kW", read_motor("tests/data/motors/eight_pole_15kW.toml"), 0.9, 40.0, 300.0,
       60.0, 100.0},
  };
}

}  // namespace imd::test
