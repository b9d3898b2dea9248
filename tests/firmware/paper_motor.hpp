#pragma once
// The two-pole motor of paper 000, Section V (hal_sim/motors/seed000.toml), for the firmware's
// stage tests, which link no file reader.
#include "control/motor_parameters.hpp"

namespace imd::test {

inline control::MotorParameters paper_motor() {
  control::MotorParameters m;
  m.Rs_Ohm = 14.0;
  m.Ls_H = 0.4;
  m.Lm_H = 0.377;
  m.Rr_Ohm = 10.1;
  m.Lr_H = 0.4128;
  m.J_kgm2 = 0.01;
  m.pole_pairs = 1;
  return m;
}

}  // namespace imd::test
