// The `limited` report (firmware/limitation.hpp): the persistence of the monitor, its window
// rule, and which limit an input on the edge of the feasible set presses against.
#include <gtest/gtest.h>

#include <cmath>

#include "control/voltage_fed_model.hpp"
#include "firmware/drive_config.hpp"
#include "firmware/limitation.hpp"
#include "firmware/stages/input_limits.hpp"

namespace imd::firmware {
namespace {

constexpr uint32_t kWindow = 400;

TEST(LimitedMonitor, RaisesAfterAWindowOfLimitedTicksAndClearsAfterAsManyFreeOnes) {
  LimitedMonitor m(kWindow);
  for (uint32_t k = 1; k < kWindow; ++k) {
    m.update(Limitation::voltage);
    ASSERT_EQ(m.limited(), Limitation::none) << k;
  }
  m.update(Limitation::voltage);
  EXPECT_EQ(m.limited(), Limitation::voltage);
  // While raised, the reason follows the latest limit.
  m.update(Limitation::current);
  EXPECT_EQ(m.limited(), Limitation::current);
  for (uint32_t k = 1; k < kWindow; ++k) {
    m.update(Limitation::none);
    ASSERT_EQ(m.limited(), Limitation::current) << k;
  }
  m.update(Limitation::none);
  EXPECT_EQ(m.limited(), Limitation::none);
}

TEST(LimitedMonitor, IgnoresALimitTouchedInLessThanHalfOfTheTicks) {
  // The sliding-mode law steps onto the voltage disk now and then (under 5 % of the ticks on
  // the realistic profile); even 49 % never fills the count.
  LimitedMonitor m(kWindow);
  for (int k = 0; k < 100 * int(kWindow); ++k) {
    m.update(k % 100 < 49 ? Limitation::voltage : Limitation::none);
    ASSERT_EQ(m.limited(), Limitation::none) << k;
  }
  m.reset();
  for (uint32_t k = 0; k < 2 * kWindow; ++k) m.update(Limitation::torque);
  EXPECT_EQ(m.limited(), Limitation::torque);
  m.reset();
  EXPECT_EQ(m.limited(), Limitation::none);
}

TEST(LimitedMonitor, WindowIsFourTimeConstantsOfTheDefaultSpeedLoop) {
  DriveConfig c;
  // 10 kHz with the 400 rad/s encoder observer: speed bandwidth min(w_c/10, 400/4) = 100 rad/s,
  // 4/100 s = 400 ticks.
  c.sample_period_s = 1e-4;
  c.encoder_observer_bandwidth_rad_s = 400.0;
  EXPECT_EQ(limited_window_ticks(c), 400u);
  // At 1 kHz the current bandwidth (w_c = 2 pi 1000/20 = 314 rad/s) limits the speed loop to
  // 31.4 rad/s: 4/31.4 s = 127 ticks.
  c.sample_period_s = 1e-3;
  EXPECT_EQ(limited_window_ticks(c), 127u);
}

TEST(InputLimitsBinding, NamesTheDiskTheInputIsNearerToLeaving) {
  control::MotorParameters motor;  // the paper-000 motor
  motor.Rs_Ohm = 14.0;
  motor.Ls_H = 0.4;
  motor.Lm_H = 0.377;
  motor.Rr_Ohm = 10.1;
  motor.Lr_H = 0.4128;
  motor.J_kgm2 = 0.01;
  motor.pole_pairs = 1;
  const auto c = control::discretize_voltage_fed(motor, 1e-4);
  InputLimitsConfig config;
  config.i_max_A = 6.0;
  const InputLimits<double> limits(motor, c, config);
  control::RotorFrameState<double> x;
  x.flux_r_AB_Wb = {0.45, 0.0};
  // 5.86 A, which the free response brings to 5.64 A, just under the 5.7 A limit: the 170 V
  // the voltage allows move the next current by up to 0.3 A, so both disks bound the input.
  x.i_s_AB_A = {5.2, 2.7};
  x.omega_mech_rad_s = 300.0;
  const double v_bus_V = 311.0;
  const control::InputDisk<double> feasible = limits.feasible(x, v_bus_V);
  // Walk the edge of the feasible disk: at each point one of the two shares is the larger,
  // and binding names it. Both names must occur: here the disk is the lens's inscribed one,
  // which touches both limits.
  int voltage = 0, current = 0;
  for (int i = 0; i < 360; ++i) {
    const double a = i * 3.141592653589793 / 180.0;
    const control::Vec2<double> v =
        feasible.center_V + feasible.radius_V * control::Vec2<double>(std::cos(a), std::sin(a));
    const Limitation l = limits.binding(x, v_bus_V, v);
    ASSERT_TRUE(l == Limitation::voltage || l == Limitation::current);
    (l == Limitation::voltage ? voltage : current) += 1;
  }
  std::printf("edge points: %d voltage, %d current\n", voltage, current);
  EXPECT_GT(voltage, 0);
  EXPECT_GT(current, 0);
  // Without a current limit, only the voltage can bind, and the reverse.
  InputLimitsConfig no_current;
  EXPECT_EQ(InputLimits<double>(motor, c, no_current).binding(x, v_bus_V, feasible.center_V),
            Limitation::voltage);
  InputLimitsConfig no_voltage;
  no_voltage.voltage_limited = false;
  no_voltage.i_max_A = 6.0;
  EXPECT_EQ(InputLimits<double>(motor, c, no_voltage).binding(x, v_bus_V, feasible.center_V),
            Limitation::current);
}

}  // namespace
}  // namespace imd::firmware
