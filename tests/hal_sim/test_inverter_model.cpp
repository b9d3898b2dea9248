// The simulated inverter's dead time and device drop (hal_sim/inverter_model.hpp), alone and on
// the board: at standstill with a DC current the steady state is I = u/Rs (model (1) with
// dI/dt = dPhi/dt = 0 and w = 0), so the voltage the inverter loses shows as a current deficit.
#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <utility>

#include "control/svpwm.hpp"
#include "hal_sim/config_error.hpp"
#include "hal_sim/inverter_model.hpp"
#include "hal_sim/scenario.hpp"
#include "hal_sim/sim_board.hpp"
#include "firmware/paper_motor.hpp"

namespace imd::sim {
namespace {

constexpr double kPeriod_s = 1e-4;
constexpr double kBus_V = 311.0;

TEST(InverterModel, IdealInverterHasNoError) {
  const InverterNonideality ideal;
  EXPECT_TRUE(ideal.ideal());
  const Vec2 e = inverter_error_V(ideal, {0.5f, 0.5f, 0.5f}, kBus_V, kPeriod_s, Vec2(3.0, 1.0));
  EXPECT_EQ(e, Vec2::Zero());
}

TEST(InverterModel, ACurrentAlongPhaseALosesFourThirdsOfThePoleError) {
  // i_a = I, i_b = i_c = -I/2: the pole errors are -E, +E, +E, and their Clarke transform is
  // (-4E/3, 0). E = t_d/T v_bus + V_d.
  const InverterNonideality inverter{1e-6, 1.5};
  const double E_V = 1e-6 / kPeriod_s * kBus_V + 1.5;
  const Vec2 e = inverter_error_V(inverter, {0.5f, 0.5f, 0.5f}, kBus_V, kPeriod_s, Vec2(2.0, 0));
  EXPECT_NEAR(e.x(), -4.0 / 3.0 * E_V, 1e-12);
  EXPECT_NEAR(e.y(), 0.0, 1e-12);
  // The error is odd in the current.
  const Vec2 e_neg =
      inverter_error_V(inverter, {0.5f, 0.5f, 0.5f}, kBus_V, kPeriod_s, Vec2(-2.0, 0));
  EXPECT_NEAR(e_neg.x(), 4.0 / 3.0 * E_V, 1e-12);
}

TEST(InverterModel, ALegThatDoesNotSwitchHasNoDeadTimeOnlyItsDrop) {
  // Phase a clamped high (duty 1): only its device drop; b and c switch.
  const InverterNonideality inverter{2e-6, 1.0};
  const double dead_V = 2e-6 / kPeriod_s * kBus_V;
  const Vec2 e = inverter_error_V(inverter, {1.0f, 0.3f, 0.3f}, kBus_V, kPeriod_s, Vec2(2.0, 0));
  const control::PhaseValues<double> pole{-1.0, dead_V + 1.0, dead_V + 1.0};
  const Vec2 expected = control::clarke(pole);
  EXPECT_NEAR(e.x(), expected.x(), 1e-12);
  EXPECT_NEAR(e.y(), expected.y(), 1e-12);
}

/// The board at rest with fixed duties for `duration_s`; returns the stator current.
Vec2 dc_current_A(const InverterNonideality& inverter, const hal::PhaseDuties& duty,
                  double duration_s) {
  SimBoardConfig config;
  config.period_s = kPeriod_s;
  config.v_bus_V = kBus_V;
  config.inverter = inverter;
  SimBoard board(test::paper_motor(), config);
  board.pwm().set_duties(duty);
  board.pwm().enable();
  const int ticks = static_cast<int>(std::lround(duration_s / kPeriod_s));
  for (int k = 0; k < ticks; ++k) board.run_tick();
  EXPECT_NEAR(board.plant().state().omega_mech_rad_s, 0.0, 1e-9);  // no torque: I is along Phi
  return board.plant().state().i_s_alphabeta_A;
}

TEST(InverterModel, TheBoardsDcCurrentShowsTheLostVoltage) {
  // Duties for u = (20 V, 0) in the linear range.
  const double u_V = 20.0;
  const control::SvpwmResult<double> pwm = control::svpwm(Vec2(u_V, 0.0), kBus_V);
  const hal::PhaseDuties duty{float(pwm.duty[0]), float(pwm.duty[1]), float(pwm.duty[2])};
  const double u_exact_V = control::clarke(control::PhaseValues<double>{
                                               duty[0] * kBus_V, duty[1] * kBus_V,
                                               duty[2] * kBus_V})
                               .x();  // the float duties' exact average voltage
  const double Rs_Ohm = test::paper_motor().Rs_Ohm;
  // 2 s is 48 rotor time constants (Lr/Rr = 41 ms): the transient is below 1e-20 of I.
  const Vec2 ideal = dc_current_A({}, duty, 2.0);
  EXPECT_NEAR(ideal.x(), u_exact_V / Rs_Ohm, 1e-9);
  const InverterNonideality inverter{1e-6, 1.2};
  const double E_V = 1e-6 / kPeriod_s * kBus_V + 1.2;
  const Vec2 real = dc_current_A(inverter, duty, 2.0);
  // RK4 sees the sign of a current far from zero: the steady state is exact to rounding.
  EXPECT_NEAR(real.x(), (u_exact_V - 4.0 / 3.0 * E_V) / Rs_Ohm, 1e-9);
  EXPECT_NEAR(real.y(), 0.0, 1e-9);
}

TEST(InverterModel, ScenarioKeysReachTheBoardAndBadValuesAreNamed) {
  const std::string paper = std::string(IMD_SOURCE_DIR) + "/hal_sim/scenarios/seed000_paper.toml";
  const Scenario s =
      load_scenario(paper, {"inverter.dead_time_s=1.5e-6", "inverter.device_drop_V=0.8"});
  EXPECT_EQ(s.inverter.dead_time_s, 1.5e-6);
  EXPECT_EQ(s.inverter.device_drop_V, 0.8);
  EXPECT_TRUE(s.dead_time_compensation);
  EXPECT_TRUE(load_scenario(paper).inverter.ideal());
  const std::pair<const char*, const char*> bad[] = {
      {"inverter.dead_time_s=-1e-6", "inverter.dead_time_s: = -1e-06: must be >= 0"},
      {"inverter.dead_time_s=2e-5", "inverter.dead_time_s: = 2e-05: must be below 0.1 *"},
      {"inverter.device_drop_V=40", "inverter.device_drop_V: = 40: must be below 0.1 *"},
      {"drive.dead_time_compensation=1", "drive.dead_time_compensation: must be true or false"},
  };
  for (const auto& [override_text, message] : bad) {
    try {
      load_scenario(paper, {override_text});
      ADD_FAILURE() << override_text << " was accepted";
    } catch (const ConfigError& e) {
      EXPECT_NE(std::string(e.what()).find(message), std::string::npos) << e.what();
    }
  }
}

}  // namespace
}  // namespace imd::sim
