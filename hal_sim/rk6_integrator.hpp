#pragma once
/// A sixth-order explicit Runge-Kutta method (Butcher's seven-stage method, Butcher 1964; the
/// tableau below) for fixed-size Eigen states. The plant uses it with steps five to ten times
/// longer than RK4's 10 us: one step (seven right-hand sides per 100 us period instead of RK4's
/// forty) while the electrical modes' bound rho stays at or below 500/s, two steps (fourteen)
/// up to 1000/s. The paper-000 motor passes 500/s above 73 rad/s; at its speed scale each test
/// motor but the 37 kW one (one step) takes two. The truncation error stays below RK4's at 10 us
/// (plant_integrator.hpp states the step rule and its error bound).
#include <cstddef>
#include <utility>

#include "hal_sim/rk4.hpp"

namespace imd::sim {

/// Butcher's tableau, c = (0, 1/3, 2/3, 1/3, 1/2, 1/2, 1). Its order was checked on a
/// non-autonomous nonlinear system in 40-digit arithmetic: halving the step divides the error by
/// 64 to 65 (2^6).
struct Rk6Tableau {
  static constexpr int kStages = 7;
  static constexpr double a[kStages][kStages] = {
      {},
      {1.0 / 3.0},
      {0.0, 2.0 / 3.0},
      {1.0 / 12.0, 1.0 / 3.0, -1.0 / 12.0},
      {-1.0 / 16.0, 9.0 / 8.0, -3.0 / 16.0, -3.0 / 8.0},
      {0.0, 9.0 / 8.0, -3.0 / 8.0, -3.0 / 4.0, 1.0 / 2.0},
      {9.0 / 44.0, -9.0 / 11.0, 63.0 / 44.0, 18.0 / 11.0, 0.0, -16.0 / 11.0},
  };
  static constexpr double b[kStages] = {11.0 / 120.0, 0.0,         27.0 / 40.0, 27.0 / 40.0,
                                        -4.0 / 15.0,  -4.0 / 15.0, 11.0 / 120.0};
};

namespace rk6_detail {

/// x + h sum_j a[I][j] k[j] as one Eigen expression (no temporaries: one pass over the state).
template <int I, typename Vector, std::size_t... J>
Vector stage(const Vector& x, double h, const Vector* k, std::index_sequence<J...>) noexcept {
  return x + h * ((Rk6Tableau::a[I][J] * k[J]) + ...);
}

template <typename Vector, typename Rhs, std::size_t... I>
void stages(const Vector& x, double h, const Rhs& f, Vector* k,
            std::index_sequence<I...>) noexcept {
  ((k[I + 1] = f(stage<int(I) + 1>(x, h, k, std::make_index_sequence<I + 1>()))), ...);
}

template <typename Vector, std::size_t... J>
Vector weighted(double h, const Vector* k, std::index_sequence<J...>) noexcept {
  return h * ((Rk6Tableau::b[J] * k[J]) + ...);
}

}  // namespace rk6_detail

/// The increment x(t + h) - x(t) of dx/dt = f(x) by one step of the method.
template <typename Vector, typename Rhs>
Vector rk6_increment(const Vector& x, double h, const Rhs& f) noexcept {
  constexpr int n = Rk6Tableau::kStages;
  Vector k[n];
  k[0] = f(x);
  rk6_detail::stages(x, h, f, k, std::make_index_sequence<n - 1>());
  return rk6_detail::weighted(h, k, std::make_index_sequence<n>());
}

/// Runs `steps` steps of size h from x (compensated, as accumulate_steps).
template <typename Vector, typename Rhs>
Vector rk6_integrate(const Vector& x, double h, int steps, const Rhs& f) noexcept {
  return accumulate_steps(x, steps, [&](const Vector& y) { return rk6_increment(y, h, f); });
}

}  // namespace imd::sim
