#pragma once
/// The structured exponential of control/block_exponential.hpp for a Metzler block X (every
/// off-diagonal entry >= 0), computed so that float keeps every entry to a small relative
/// error, however small the entry: the drive recomputes its model with it in float on the MCU.
///
///   B = [X  I  0]        exp(B) = [E  Y  Z]
///       [0  gI I]                 [0  eI wI]
///       [0  0  0]                 [0  0  I]
///
/// Idea. B is Metzler too, so B + mu I is entrywise >= 0 for mu = max(0, -X_ii, -g), and
/// exp(B/2^s) = exp(-mu/2^s) exp((B + mu I)/2^s). The series of a nonnegative matrix has only
/// nonnegative terms and squaring multiplies nonnegative matrices: no subtraction anywhere, so
/// rounding errors stay relative to each entry (a sum or product of nonnegative numbers with
/// relative errors <= r has relative error <= r). Both generators of the voltage-fed model
/// are Metzler (voltage_fed_model.hpp): A3 (couplings alpha Lm, alpha beta, 1/sigma) and its
/// additive compound (1/sigma, alpha Lm, alpha beta); with viscous friction g = -f delta <= 0.
///
/// Error bound, componentwise, with u = 2^-24 in float (first order in u; gamma_n = n u):
/// - Series of kTerms = 12 terms on the scaled matrix (infinity norm theta <= 1/4 for the X and
///   g parts, couplings a = 2^-s <= 1). A term is a 3-term dot product of nonnegative numbers
///   (gamma_3), times 1/(n+1) (rounded: 2u): term n carries n (gamma_3 + 2u) = 5n u, at most
///   60 u; the 12 additions of nonnegative terms add 12 u. The factor exp(-mu/2^s) (expf,
///   within 1 ulp = 2u) and its product add 3 u: r_0 <= 75 u.
/// - Truncation, relative to each entry: the scaled matrix's entries within blocks are <= theta
///   (row sums), the couplings a <= 1. An entry (i, j) of exp is a sum over walks i -> j,
///   weighted by their steps' product over n!, and its leading term L sums the shortest walks
///   (length d). In the drive's graphs (chains 0 -> 1 <-> 2 inside X, then X -> Y -> Z) every
///   walk of length n is a shortest one with closed excursions inserted at n - d of its steps
///   (a coupling is never in an excursion: the blocks are upper triangular), and the
///   excursions of length m from a node weigh at most theta^m. So the terms n > kTerms sum to
///   at most L sum_{m > kTerms - d} theta^m / m!, with d <= 2 in E, 3 in Y, 4 in Z: for
///   kTerms = 12 and theta = 1/4, below 0.25^9 / 9! = 1.1e-11 of the entry, 2e-4 u.
/// - Squaring: E^2, E Y + e Y, E Z + w Y + eta Z are sums of at most 5 nonnegative products:
///   r_{k+1} <= 2 r_k + 5 u, so after s squarings r_s <= 2^s (r_0 + 5 u) <= 2^s 80 u.
/// So every entry of E, Y, Z, e and w is within 2^s 80 u of its own value, where 2^s < 8 theta_0
/// for theta_0 = max(|X + mu I|, g + mu, mu) before scaling (2^s = 1 when theta_0 <= 1/4).
/// For the test motors at 0.5x to 2x their rotor resistance (tests/control/
/// test_float_discretization.cpp) theta_0 <= 0.22, 0.45 and 4.5 at 50 us, 100 us and 1 ms:
/// s <= 0, 1 and 5, i.e. 80 u = 4.8e-6, 160 u = 9.5e-6 and 2560 u = 1.5e-4 at worst. Measured:
/// at most 35 u (2e-6) on any coefficient; the bound is loose because each squaring doubles
/// the worst case, not the typical error.
#include <Eigen/Core>
#include <algorithm>
#include <cmath>

#include "control/block_squaring.hpp"
namespace imd::control {

/// The blocks of exp(B) that are kept, for an N x N block X (N = 3 for the electrical models,
/// 1 for the mechanical one, where E, Y, Z are exp(g)-weighted integrals of 1).
template <typename T, int N>
struct MetzlerExponential {
  using Matrix = Eigen::Matrix<T, N, N>;
  Matrix e_x = Matrix::Identity();  ///< E = exp(X)
  Matrix y = Matrix::Zero();        ///< Y, the block right of E
  Matrix z = Matrix::Zero();        ///< Z, the top-right block
  T e_g = T(1);                     ///< exp(g)
  T w = T(0);                       ///< w = phi1(g) = (exp(g) - 1)/g
};

/// Largest number of squarings (theta_0 up to 2^64 / 4): the loop's bound, never reached.
inline constexpr int kMetzlerMaxSquarings = 64;

/// theta_0 of the bound above: the largest of |X + mu I| (infinity norm), g + mu and mu.
template <typename T, int N>
T metzler_shifted_norm(const Eigen::Matrix<T, N, N>& x, T g) noexcept {
  T mu = std::max(T(0), -g);
  for (int i = 0; i < N; ++i) mu = std::max(mu, -x(i, i));
  const Eigen::Matrix<T, N, N> shifted = x + mu * Eigen::Matrix<T, N, N>::Identity();
  return std::max({shifted.cwiseAbs().rowwise().sum().maxCoeff(), std::abs(g + mu), mu});
}

/// Number of squarings s of the bound above: 2^-s theta_0 <= 1/4 with the smallest s.
template <typename T, int N>
int metzler_squarings(const Eigen::Matrix<T, N, N>& x, T g) noexcept {
  const T theta = metzler_shifted_norm(x, g);
  int squarings = 0;
  T a = T(1);
  while (theta * a > T(0.25) && squarings < kMetzlerMaxSquarings) {
    a *= T(0.5);
    ++squarings;
  }
  return squarings;
}

/// exp of [X I 0; 0 gI I; 0 0 0] for a Metzler X (off-diagonal entries >= 0; others give no
/// bound). Not for tick context: start-up and the service loop. No allocation; fixed trip
/// counts apart from the squarings (log2 of the norm, at most kMetzlerMaxSquarings).
template <typename T, int N>
MetzlerExponential<T, N> metzler_block_exponential(const Eigen::Matrix<T, N, N>& x, T g) noexcept {
  using Matrix = Eigen::Matrix<T, N, N>;
  constexpr int kTerms = 12;

  // Shift to a nonnegative matrix: B + mu I = [X + mu I, I, 0; 0, (g + mu) I, I; 0, 0, mu I].
  T mu = std::max(T(0), -g);
  for (int i = 0; i < N; ++i) mu = std::max(mu, -x(i, i));
  const int squarings = metzler_squarings(x, g);
  T a = T(1);  // 2^-s, exact
  for (int k = 0; k < squarings; ++k) a *= T(0.5);
  Matrix xs = x * a;
  for (int i = 0; i < N; ++i) xs(i, i) = (x(i, i) + mu) * a;
  for (int i = 0; i < N; ++i) {
    for (int j = 0; j < N; ++j) xs(i, j) = std::max(xs(i, j), T(0));  // -0 and rounding
  }
  const T gs = std::max((g + mu) * a, T(0));
  const T hs = mu * a;

  // Taylor series of the scaled, shifted matrix. Its n-th power has top row [X^n, P_n, Q_n],
  // middle row [0, g^n I, c_n I] and bottom row [0, 0, h^n I], with P_{n+1} = a X^n + g P_n,
  // Q_{n+1} = a P_n + h Q_n, c_{n+1} = a g^n + h c_n: all terms nonnegative.
  MetzlerExponential<T, N> r;
  Matrix x_power = Matrix::Identity();  // X^n / n!
  Matrix p = Matrix::Zero();            // P_n / n!
  Matrix q = Matrix::Zero();            // Q_n / n!
  T g_power = T(1), c = T(0);
  for (int n = 0; n < kTerms; ++n) {
    const T next = T(1) / T(n + 1);
    const Matrix x_next = (x_power * xs) * next;
    const Matrix p_next = (a * x_power + gs * p) * next;
    const Matrix q_next = (a * p + hs * q) * next;
    const T c_next = (a * g_power + hs * c) * next;
    g_power = g_power * gs * next;
    x_power = x_next;
    p = p_next;
    q = q_next;
    c = c_next;
    r.e_x += x_power;
    r.y += p;
    r.z += q;
    r.e_g += g_power;
    r.w += c;
  }
  // Undo the shift: every block of exp(B/2^s) is exp(-mu/2^s) times the computed one; the
  // bottom block, exp(0) = I, is exact without it.
  const T unshift = std::exp(-hs);
  r.e_x *= unshift;
  r.y *= unshift;
  r.z *= unshift;
  r.e_g *= unshift;
  r.w *= unshift;

  square_blocks(r, squarings);
  return r;
}

}  // namespace imd::control
