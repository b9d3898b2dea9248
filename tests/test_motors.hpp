#pragma once
// The motors the tests run on: both papers' motors as shipped, and two more from tests/data.
// Each comes with magnitudes typical of its operation, used to draw random test states.
#include <string>
#include <vector>

#include "control/motor_parameters.hpp"
#include "hal_sim/motor_file.hpp"

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

inline std::vector<TestMotor> test_motors() {
  return {
      {"seed000", sim::load_motor_file(source_path("hal_sim/motors/seed000.toml")), 0.5, 3.0, 300.0,
       250.0, 1.0},
      {"seed001", sim::load_motor_file(source_path("hal_sim/motors/seed001.toml")), 1.0, 200.0,
       300.0, 150.0, 200.0},
      {"small_4pole_750W",
       sim::load_motor_file(source_path("tests/data/motors/small_4pole_750W.toml")), 0.8, 2.0,
       300.0, 150.0, 4.0},
      {"six_pole_7kW", sim::load_motor_file(source_path("tests/data/motors/six_pole_7kW.toml")),
       0.9, 25.0, 300.0, 100.0, 60.0},
  };
}

}  // namespace imd::test
