#pragma once
/// Classic fourth-order Runge-Kutta for fixed-size Eigen states, and the compensated
/// accumulation of steps that every fixed-step scheme of the plant shares.
namespace imd::sim {

/// The RK4 increment x(t + h) - x(t) of dx/dt = f(x). f takes the state and returns its
/// derivative.
template <typename Vector, typename Rhs>
Vector rk4_increment(const Vector& x, double h, const Rhs& f) noexcept {
  const Vector k1 = f(x);
  const Vector k2 = f(x + (0.5 * h) * k1);
  const Vector k3 = f(x + (0.5 * h) * k2);
  const Vector k4 = f(x + h * k3);
  return (h / 6.0) * (k1 + 2.0 * k2 + 2.0 * k3 + k4);
}

/// Runs `steps` steps from x, each adding increment(x). The increments are accumulated with
/// compensated (Kahan) summation, so that over many small steps the state does not drift by
/// rounding: the speed of a motor at 300 rad/s changes by ~1e-5 rad/s per step, 1e-8 of its
/// value.
template <typename Vector, typename Increment>
Vector accumulate_steps(Vector x, int steps, const Increment& increment) noexcept {
  Vector carry = Vector::Zero();
  for (int i = 0; i < steps; ++i) {
    const Vector corrected = increment(x) - carry;
    const Vector sum = x + corrected;
    carry = (sum - x) - corrected;
    x = sum;
  }
  return x;
}

/// Runs `steps` RK4 steps of size h from x (compensated, as accumulate_steps).
template <typename Vector, typename Rhs>
Vector integrate(const Vector& x, double h, int steps, const Rhs& f) noexcept {
  return accumulate_steps(x, steps, [&](const Vector& y) { return rk4_increment(y, h, f); });
}

}  // namespace imd::sim
