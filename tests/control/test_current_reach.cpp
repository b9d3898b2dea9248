// The currents a current loop reaches under the voltage limit (control/current_reach.hpp),
// against the exact sampled model stepped tick by tick with the feedback (2) and a stator
// voltage on or inside the limit, on every test motor.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <complex>
#include <limits>
#include <numbers>
#include <random>

#include "control/current_reach.hpp"
#include "control/voltage_fed_model.hpp"
#include "test_motors.hpp"

namespace imd::control {
namespace {

constexpr double kTick_s = 1e-4;

/// One run of `ticks` periods from x, the stator voltage (rotor frame) of each tick chosen by
/// `voltage(j)`; returns the final current and the largest drift of the rotor flux.
template <typename Voltage>
std::pair<Vec2<double>, double> run(const VoltageFedModel<double>& model,
                                    const MotorParameters& motor, RotorFrameState<double> x,
                                    int ticks, Voltage voltage) {
  const auto k = derive_voltage_fed(motor);
  const Vec2<double> flux0 = x.flux_r_AB_Wb;
  double drift = 0.0;
  for (int j = 0; j < ticks; ++j) {
    // v~ = u_AB - sigma p w J (I~ + beta Phi~): the feedback (2) the current loop runs under.
    const Vec2<double> v =
        voltage(j) - k.sigma_H * motor.pole_pairs * x.omega_mech_rad_s *
                         J_times<double>(x.i_s_AB_A + k.beta_per_H * x.flux_r_AB_Wb);
    const double omega = x.omega_mech_rad_s;
    x = model.predict(x, v, 0.0);
    x.omega_mech_rad_s = omega;  // the disk takes the speed of its state
    drift = std::max(drift, (x.flux_r_AB_Wb - flux0).norm());
  }
  return {x.i_s_AB_A, drift};
}

TEST(CurrentReach, IsTheDiskTheExactModelReaches) {
  std::mt19937_64 rng(11);
  std::uniform_real_distribution<double> unit(-1.0, 1.0),
      angle(-std::numbers::pi, std::numbers::pi);
  for (const test::TestMotor& m : test::test_motors()) {
    const VoltageFedCoefficients c = discretize_voltage_fed(m.parameters, kTick_s);
    const VoltageFedModel<double> model(c);
    const CurrentReach<double> reach(m.parameters, c);
    const auto k = derive_voltage_fed(m.parameters);
    for (int trial = 0; trial < 100; ++trial) {
      RotorFrameState<double> x;
      x.flux_r_AB_Wb = m.flux_Wb * Vec2<double>(unit(rng), unit(rng));
      x.i_s_AB_A = m.current_A * Vec2<double>(unit(rng), unit(rng));
      x.omega_mech_rad_s = 2.0 * m.speed_rad_s * unit(rng);
      const double v_max_V = m.voltage_V * (0.2 + std::abs(unit(rng)));
      for (const int ticks : {1, 2, 5, 9}) {
        const CurrentDisk<double> disk =
            reach.disk(x.flux_r_AB_Wb, x.i_s_AB_A, x.omega_mech_rad_s, v_max_V, ticks);
        // The disk holds the rotor flux still; the model moves it. The centre is off by at
        // most sum_j |A|^(m-1-j) |a21 - i b2 sigma p w beta| times the flux's drift (the
        // forcing term of each tick), plus rounding on the current's scale.
        const double turn = c.b2 * k.sigma_H * m.parameters.pole_pairs * x.omega_mech_rad_s;
        const double gain = std::hypot(c.a22, turn),
                     forcing = std::hypot(c.a21, turn * k.beta_per_H);
        double gains = 0.0;
        for (int j = 0; j < ticks; ++j) gains += std::pow(gain, j);
        const double rounding = 1e-12 * (m.current_A + disk.radius_A);
        // No stator voltage: the free response, the centre.
        const auto [free, drift0] = run(model, m.parameters, x, ticks,
                                        [](int) -> Vec2<double> { return Vec2<double>::Zero(); });
        EXPECT_LE((free - disk.center_A).norm(), gains * forcing * drift0 + rounding)
            << m.name << " ticks " << ticks;
        // Every tick's voltage on the limit, turned so that each tick's contribution
        // A^(m-1-j) b2 u_j points one way: the disk's edge in that direction.
        const double direction = angle(rng);
        const std::complex<double> A(c.a22, -turn);
        const auto edge = [&](int j) -> Vec2<double> {
          const std::complex<double> power = std::pow(A, ticks - 1 - j);
          const std::complex<double> u =
              v_max_V * std::polar(1.0, direction) * std::conj(power) / std::abs(power);
          return Vec2<double>(u.real(), u.imag()) * (c.b2 > 0 ? 1.0 : -1.0);
        };
        const auto [far, drift1] = run(model, m.parameters, x, ticks, edge);
        EXPECT_NEAR((far - disk.center_A).norm(), disk.radius_A,
                    gains * forcing * drift1 + rounding)
            << m.name << " ticks " << ticks;
        // Voltages drawn inside the limit stay inside the disk.
        const auto [inside, drift2] = run(model, m.parameters, x, ticks, [&](int) -> Vec2<double> {
          const double turned = angle(rng);
          return v_max_V * std::sqrt(std::abs(unit(rng))) *
                 Vec2<double>(std::cos(turned), std::sin(turned));
        });
        EXPECT_LE((inside - disk.center_A).norm(),
                  disk.radius_A + gains * forcing * drift2 + rounding)
            << m.name << " ticks " << ticks;
      }
    }
  }
}

TEST(CurrentReach, NoVoltageLimitReachesEveryCurrent) {
  const test::TestMotor m = test::test_motors()[0];
  const CurrentReach<double> reach(m.parameters, discretize_voltage_fed(m.parameters, kTick_s));
  const CurrentDisk<double> disk =
      reach.disk({0.5, 0.0}, {1.0, 2.0}, 100.0, std::numeric_limits<double>::infinity(), 3);
  EXPECT_TRUE(disk.unlimited());
  EXPECT_TRUE(disk.contains({1e6, -1e6}));
  EXPECT_TRUE(reach.disk({0.5, 0.0}, {1.0, 2.0}, 100.0, NAN, 3).unlimited());
}

TEST(CurrentReach, TheCurrentLimitNarrowsTheDisk) {
  // A reach of radius 3 A around (4, 0) against |i| <= 5 A: the lens on the axis is [1, 5],
  // so the largest disk inside both has radius 2 A around (3, 0).
  const CurrentDisk<double> both = within_current_limit(CurrentDisk<double>{{4.0, 0.0}, 3.0}, 5.0);
  EXPECT_NEAR(both.radius_A, 2.0, 1e-15);
  EXPECT_NEAR((both.center_A - Vec2<double>(3.0, 0.0)).norm(), 0.0, 1e-15);
  // Inside the limit the reach is kept as it is; no limit keeps it too.
  EXPECT_EQ(within_current_limit(CurrentDisk<double>{{1.0, 0.0}, 1.0}, 5.0).radius_A, 1.0);
  EXPECT_EQ(within_current_limit(CurrentDisk<double>{{9.0, 0.0}, 1.0},
                                 std::numeric_limits<double>::infinity())
                .radius_A,
            1.0);
}

}  // namespace
}  // namespace imd::control
