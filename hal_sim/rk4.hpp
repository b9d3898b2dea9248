#pragma once
/// Classic fourth-order Runge-Kutta for fixed-size Eigen states.
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

/// Runs `steps` RK4 steps of size h from x. The increments are accumulated with compensated
/// (Kahan) summation, so that over many small steps the state does not drift by rounding: the
/// speed of a motor at 300 rad/s changes by ~1e-5 rad/s per step, 1e-8 of its value.
template <typename Vector, typename Rhs>
Vector integrate(Vector x, double h, int steps, const Rhs& f) noexcept {
  Vector carry = Vector::Zero();
  for (int i = 0; i < steps; ++i) {
    const Vector corrected = rk4_increment(x, h, f) - carry;
    const Vector sum = x + corrected;
    carry = (sum - x) - corrected;
    x = sum;
  }
  return x;
}

}  // namespace imd::sim
