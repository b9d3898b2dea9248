#pragma once
// The six motors of tests/test_motors.hpp on their realistic boards (0.55 kW to the paper-001
// 37 kW machine, one to four pole pairs): the scenario files the sweeps take them from, and
// when a drive on them runs.
#include "firmware/drive_config.hpp"
#include "firmware/protection/magnetizing_timeout.hpp"
#include "hal_sim/scenario.hpp"

namespace imd::sim::test_boards {

inline constexpr const char* kRealistic[] = {"hal_sim/scenarios/seed000_realistic.toml",
                                             "hal_sim/scenarios/seed001_realistic.toml",
                                             "tests/data/scenarios/small_4pole_750W_realistic.toml",
                                             "tests/data/scenarios/six_pole_7kW_realistic.toml",
                                             "tests/data/scenarios/two_pole_550W_realistic.toml",
                                             "tests/data/scenarios/eight_pole_15kW_realistic.toml"};

/// `s` with its plant off the motor record by the ratios (plant over record) of the rotor and
/// stator resistances, the magnetizing inductance (the leakages kept, as when the iron
/// saturates) and the inertia.
inline Scenario with_plant_error(Scenario s, double Rr, double Rs, double Lm, double J) {
  const control::MotorParameters& m = s.motor;
  s.plant.Rr_Ohm = Rr * m.Rr_Ohm;
  s.plant.Rs_Ohm = Rs * m.Rs_Ohm;
  s.plant.Lm_H = Lm * m.Lm_H;
  s.plant.Ls_H = m.Ls_H + s.plant.Lm_H - m.Lm_H;
  s.plant.Lr_H = m.Lr_H + s.plant.Lm_H - m.Lm_H;
  s.plant.J_kgm2 = J * m.J_kgm2;
  return s;
}

/// When the drive runs, from enable at 0: the offset calibration (256 ticks), then the model's
/// magnetizing time (firmware/protection/magnetizing_timeout.hpp) and a fifth more for the
/// current's rise and the flux estimate's lag. 0.21 s for the paper-000 motor, 1.6 s for the
/// 15 kW (tau_r 0.35 s). A bound: that time is under the magnetizer's default current, and a
/// board that sets a larger one (the 37 kW's 90 A: running at 0.19 s, here 2.1 s) is sooner.
inline double running_by_s(const Scenario& s) {
  return 256 * s.sample_period_s +
         1.2 * double(firmware::magnetizing_time_s(s.motor, Real(s.magnetized_fraction)));
}

}  // namespace imd::sim::test_boards
