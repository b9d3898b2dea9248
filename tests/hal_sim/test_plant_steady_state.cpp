// The continuous plant against textbook steady states that are derived independently of
// model (1): the per-phase equivalent circuit under balanced AC supply, and DC-injection
// braking. The speed is held by a very large inertia, as on a dynamometer.
#include <gtest/gtest.h>

#include <cmath>
#include <complex>
#include <numbers>

#include "hal_sim/induction_motor_plant.hpp"
#include "test_motors.hpp"

namespace imd::sim {
namespace {

using Complex = std::complex<double>;

control::MotorParameters on_dynamometer(control::MotorParameters m) {
  m.J_kgm2 = 1e12;  // the speed changes by < 1e-9 rad/s over the run
  m.friction_Nms = 0.0;
  return m;
}

TEST(PlantSteadyState, BalancedSupplyMatchesTheEquivalentCircuit) {
  const control::MotorParameters m = on_dynamometer(test::test_motors()[0].parameters);
  const double omega_supply_rad_s = 2.0 * std::numbers::pi * 50.0;
  const double voltage_V = 300.0;  // peak phase voltage = space-vector magnitude
  const double omega_mech_rad_s = 280.0;
  const double slip_rad_s = omega_supply_rad_s - m.pole_pairs * omega_mech_rad_s;

  // Phasors (space-vector amplitudes) of the stator and rotor currents, stationary frame:
  //   U = Rs I + j we (Ls I + Lm Ir),   0 = Rr Ir + j ws (Lr Ir + Lm I).
  const Complex j(0.0, 1.0);
  const Complex z11 = m.Rs_Ohm + j * omega_supply_rad_s * m.Ls_H;
  const Complex z12 = j * omega_supply_rad_s * m.Lm_H;
  const Complex z21 = j * slip_rad_s * m.Lm_H;
  const Complex z22 = m.Rr_Ohm + j * slip_rad_s * m.Lr_H;
  const Complex det = z11 * z22 - z12 * z21;
  const Complex i_stator = voltage_V * z22 / det;
  const Complex i_rotor = -voltage_V * z21 / det;
  // Air-gap power over synchronous mechanical speed; 3/2 for peak-value space vectors.
  const double torque_Nm = 1.5 * m.pole_pairs * std::norm(i_rotor) * m.Rr_Ohm / slip_rad_s;

  // The voltage is held over steps of h = 1 us and sampled at mid-step, so the staircase has
  // the sinusoid's phase. Its fundamental is smaller by (we h)^2/24 = 4e-9, and the ripple
  // between the sample instants integrates to zero at the instants themselves (to second
  // order, again ~1e-8). The slowest electrical mode at this speed decays at 77 1/s, so after
  // 0.6 s it is below e^-40. Hence 1e-6 relative is a safe bound that a wrong equation misses
  // by orders of magnitude.
  const double h_s = 1e-6;
  InductionMotorPlant plant(m, {h_s, 1});
  PlantState start;
  start.omega_mech_rad_s = omega_mech_rad_s;
  plant.set_state(start);
  const int steps = 600000;
  for (int k = 0; k < steps; ++k) {
    const double phase = omega_supply_rad_s * (k + 0.5) * h_s;
    plant.step_voltage(voltage_V * Vec2(std::cos(phase), std::sin(phase)), 0.0);
  }
  const Complex expected_current = i_stator * std::exp(j * omega_supply_rad_s * (steps * h_s));
  const Vec2& i = plant.state().i_s_alphabeta_A;
  EXPECT_LE(std::abs(Complex(i.x(), i.y()) - expected_current) / std::abs(expected_current), 1e-6);
  EXPECT_NEAR(plant.torque_Nm(), torque_Nm, 1e-6 * std::abs(torque_Nm));
  EXPECT_GT(torque_Nm, 0.0);  // below synchronous speed the machine motors
  std::printf("AC steady state: |I| %.9f A (circuit %.9f A), torque %.9f N m (circuit %.9f N m)\n",
              i.norm(), std::abs(i_stator), plant.torque_Nm(), torque_Nm);
}

TEST(PlantSteadyState, DcInjectionBrakingTorque) {
  // A DC stator voltage on a spinning rotor: in steady state I = U / Rs and the rotor sees a
  // field slipping at w = p w_mech, giving the braking torque
  //   T = -3/2 p (Lm^2 / Lr) |I|^2 alpha w / (alpha^2 + w^2),  alpha = Rr / Lr.
  for (const auto& motor : test::test_motors()) {
    SCOPED_TRACE(motor.name);
    const control::MotorParameters m = on_dynamometer(motor.parameters);
    const double omega_mech_rad_s = 100.0;
    const Vec2 u_V(0.6, -0.8);  // 1 V DC; the steady state scales linearly
    InductionMotorPlant plant(m, {1e-4, 10});
    PlantState start;
    start.omega_mech_rad_s = omega_mech_rad_s;
    plant.set_state(start);
    // Slowest electrical mode of the test motors at this speed: real part < -2 1/s for the
    // 37 kW motor (alpha = 2.2 1/s); 20 s leaves e^-40.
    for (int k = 0; k < 200000; ++k) plant.step_voltage(u_V, 0.0);
    const Vec2 expected_current = u_V / m.Rs_Ohm;
    const double alpha = m.Rr_Ohm / m.Lr_H;
    const double w = m.pole_pairs * omega_mech_rad_s;
    const double expected_torque = -1.5 * m.pole_pairs * m.Lm_H * m.Lm_H / m.Lr_H *
                                   expected_current.squaredNorm() * alpha * w /
                                   (alpha * alpha + w * w);
    // Constant input: RK4 at h = 1e-5 s converges to the exact equilibrium (truncation acts on
    // the decaying transient only), so what is left is rounding: 1e-9 relative.
    EXPECT_LE((plant.state().i_s_alphabeta_A - expected_current).norm() / expected_current.norm(),
              1e-9);
    EXPECT_NEAR(plant.torque_Nm(), expected_torque, 1e-9 * std::abs(expected_torque));
  }
}

}  // namespace
}  // namespace imd::sim
