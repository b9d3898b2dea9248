#pragma once
/// Classic fourth-order Runge-Kutta step for fixed-size Eigen states.
namespace imd::sim {

/// Advances x by one step h of dx/dt = f(x). f takes the state and returns its derivative.
template <typename Vector, typename Rhs>
Vector rk4_step(const Vector& x, double h, const Rhs& f) noexcept {
  const Vector k1 = f(x);
  const Vector k2 = f(x + (0.5 * h) * k1);
  const Vector k3 = f(x + (0.5 * h) * k2);
  const Vector k4 = f(x + h * k3);
  return x + (h / 6.0) * (k1 + 2.0 * k2 + 2.0 * k3 + k4);
}

}  // namespace imd::sim
