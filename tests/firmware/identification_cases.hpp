#pragma once
// The motors and boards the identification tests run on: a nameplate, and a board with
// realistic sensors (ADC noise and per-phase offsets, 12 bits) and an inverter with dead time
// and device drop. Paper 000's on a 311 V bus with a 10 A ADC, paper 001's 37 kW on 540 V with
// a 250 A ADC, the 0.55 kW, 0.75 kW, 7.5 kW and 15 kW motors on 540 V with ADCs sized for them.
#include <gtest/gtest.h>

#include <string>

#include "control/motor_parameters.hpp"
#include "firmware/identification/nameplate.hpp"
#include "hal_sim/sim_board.hpp"
#include "test_motors.hpp"

namespace imd::firmware::test_cases {

struct Case {
  const char* motor;
  Nameplate nameplate;
  double v_bus_V, i_max_A, adc_full_scale_A, adc_noise_A, adc_offset_A, dead_time_s, drop_V;
};

inline const Case kSeed000{"seed000", {220.0, 2.5, 50.0, 1}, 311.0, 6.0, 10.0, 0.01, 0.02, 1e-6,
                           1.0};
inline const Case kSeed001{"seed001", {400.0, 70.0, 50.0, 2}, 540.0, 150.0, 250.0, 0.5, 0.5, 2e-6,
                           1.5};
inline const Case kSmall{
    "small_4pole_750W", {400.0, 1.9, 50.0, 2}, 540.0, 6.0, 10.0, 0.01, 0.02, 1e-6, 1.0};
inline const Case kSixPole{
    "six_pole_7kW", {400.0, 14.0, 50.0, 3}, 540.0, 40.0, 50.0, 0.05, 0.1, 1.5e-6, 1.2};
inline const Case kTwoPole{
    "two_pole_550W", {400.0, 1.4, 50.0, 1}, 540.0, 5.0, 10.0, 0.01, 0.02, 1e-6, 1.0};
inline const Case kEightPole{
    "eight_pole_15kW", {400.0, 32.0, 50.0, 4}, 540.0, 80.0, 150.0, 0.15, 0.3, 2e-6, 1.5};

inline sim::SimBoardConfig board_for(const Case& c, uint32_t encoder_cpr = 8192) {
  sim::SimBoardConfig b;
  b.v_bus_V = c.v_bus_V;
  b.adc.full_scale_A = c.adc_full_scale_A;
  b.adc.noise_A = c.adc_noise_A;
  b.adc.offset_A = {c.adc_offset_A, -c.adc_offset_A, 0.5 * c.adc_offset_A};
  b.adc.bus_full_scale_V = 2.0 * c.v_bus_V;
  b.inverter.dead_time_s = c.dead_time_s;
  b.inverter.device_drop_V = c.drop_V;
  b.encoder_cpr = encoder_cpr;
  return b;
}

inline control::MotorParameters motor_named(const char* name) {
  for (const auto& m : test::test_motors()) {
    if (m.name == name) return m.parameters;
  }
  ADD_FAILURE() << "no test motor " << name;
  return {};
}

inline std::string case_name(const ::testing::TestParamInfo<Case>& p) {
  return p.param.motor;
}

}  // namespace imd::firmware::test_cases
