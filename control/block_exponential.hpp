#pragma once
/// The exponential of the structured block matrix that the exact sampled models need, by a
/// fixed-size method with a proven error bound: Taylor series on a scaled copy, then squaring.
/// It replaces a general matrix exponential (Eigen's Pade 3..13 with an LU solve), which on
/// the MCU cost about 30 KB of flash and 13 KiB of stack for a 9x9 matrix that is mostly
/// identity and zero blocks.
///
/// The matrix is, with X a 3x3 block and g a scalar,
///
///   B = [X  I  0]        exp(B) = [E  Y  Z]
///       [0  gI I]                 [0  eI wI]
///       [0  0  0]                 [0  0  I]
///
/// E = exp(X) and e = exp(g); Y, Z and w are the weighted integrals that Van Loan's method
/// yields (voltage_fed_model.cpp). Only E, Y, Z, e and w are stored: 27 + 2 numbers instead of
/// 81, and a squaring costs three 3x3 products instead of one 9x9.
///
/// Error. The scaled matrix B/2^s has its X and g parts of infinity norm theta <= 1/4. The
/// identity blocks are nilpotent couplings: the n-th power's top row is bounded by
/// n^2 theta^(n-2) (at most two couplings, each picked at one of n places). The series is cut
/// after kTerms = 18 terms: the first term left out is below 19^2 0.25^17 / 19! = 2e-25 of the
/// unit-sized blocks, and the ones after it fall faster than geometrically: truncation is far
/// below double's rounding (a proven bound). What is left is rounding, which is estimated, not
/// proven: the series sums to a few ulp, and each squaring roughly doubles the relative error
/// it receives and adds a few ulp of its own; with 2^s < 8 theta_0 (theta_0 = |X| + |g| before
/// scaling) that is about (1 + 4 theta_0) x 8 ulp of the blocks' size. Measured against a
/// long-double reference (tests/control/test_block_exponential.cpp) it holds on random
/// matrices up to theta_0 = 8 and on the motors' matrices up to a 10 ms period (theta_0 up to
/// 22); on random non-normal matrices of larger norm it is exceeded (by 1.1..3.4 x at 22..100).
/// The drive's matrices have theta_0 well under 1 at 100 us, and up to 22 at 10 ms, the
/// longest sample period a scenario accepts, where the estimate still held.
/// In float the same holds in float's ulp; the series' remainder is far below it as well.
#include <Eigen/Core>
#include <cmath>

#include "control/block_squaring.hpp"
namespace imd::control {

template <typename T>
struct BlockExponential {
  using Matrix3 = Eigen::Matrix<T, 3, 3>;
  Matrix3 e_x = Matrix3::Identity();  ///< E = exp(X)
  Matrix3 y = Matrix3::Zero();        ///< Y, the block right of E
  Matrix3 z = Matrix3::Zero();        ///< Z, the top-right block
  T e_g = T(1);                       ///< exp(g)
  T w = T(0);                         ///< w = phi1(g) = (exp(g) - 1)/g
};

/// exp of [X I 0; 0 gI I; 0 0 0] (see above). Not for tick context: start-up and the
/// service loop. No allocation, no recursion; the loops have fixed trip counts, apart from
/// the number of squarings, which grows as log2 of |X| and |g| and is bounded by 64.
template <typename T>
BlockExponential<T> block_exponential(const Eigen::Matrix<T, 3, 3>& x, T g) noexcept {
  using Matrix3 = Eigen::Matrix<T, 3, 3>;
  constexpr int kTerms = 18;
  constexpr T kThetaMax = T(0.25);

  // Scaling: B/2^s = [X/2^s, aI, 0; 0, (g/2^s) I, aI; 0 0 0] with a = 2^-s.
  const T theta = x.cwiseAbs().rowwise().sum().maxCoeff() + std::abs(g);
  int squarings = 0;
  T a = T(1);
  while (theta * a > kThetaMax && squarings < 64) {
    a *= T(0.5);
    ++squarings;
  }
  const Matrix3 xs = x * a;
  const T gs = g * a;

  // Taylor series. The n-th power of the scaled B has top row [X^n, P_n, Q_n] and middle row
  // [0, g^n I, c_n I], with P_{n+1} = a X^n + g P_n, Q_{n+1} = a P_n and c_{n+1} = a g^n.
  BlockExponential<T> r;
  Matrix3 x_power = Matrix3::Identity();  // X^n / n!
  Matrix3 p = Matrix3::Zero();            // P_n / n!
  Matrix3 q = Matrix3::Zero();            // Q_n / n!
  T g_power = T(1);                       // g^n / n!
  T c = T(0);                             // c_n / n!
  for (int n = 0; n < kTerms; ++n) {
    const T next = T(1) / T(n + 1);
    const Matrix3 x_next = (x_power * xs) * next;
    const Matrix3 p_next = (a * x_power + gs * p) * next;
    const Matrix3 q_next = (a * p) * next;
    const T c_next = a * g_power * next;
    const T g_next = g_power * gs * next;
    x_power = x_next;
    p = p_next;
    q = q_next;
    g_power = g_next;
    c = c_next;
    r.e_x += x_power;
    r.y += p;
    r.z += q;
    r.e_g += g_power;
    r.w += c;
  }

  square_blocks(r, squarings);
  return r;
}

}  // namespace imd::control
