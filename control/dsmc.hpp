#pragma once
/// Discrete sliding-mode control of speed and squared rotor-flux modulus, paper 000 Section III,
/// on the exact sampled model. One call per period, tick context.
///
/// With xi1, lambda1, xi2, lambda2 of (7) and w = B_k v~ (8), B_k = [lambda1^T; lambda2^T]:
///   speed: w_alpha = w_eq_alpha = w_ref_{k+1} - xi1 - (load term), clamped to its bound;
///   flux:  S2_{k+1} = a w_beta^2 + b w_beta + c (10), solved for S2_{k+1} = 0 by root (11).
/// Departures from the paper, each argued in docs/control.md:
///   * root (11) in the cancellation-free form -2c / (b + sqrt(D)) (for b >= 0);
///   * for a negative discriminant the vertex -b/(2a) (the minimiser of S2_{k+1}) rather than
///     -b/a, which leaves S2_{k+1} = -D/(4a) instead of c;
///   * saturation keeps the sign of the unsaturated control in both channels;
///   * the bounds w0_alpha, w0_beta are intervals derived each period from the feasible input
///     disk (InputDisk), flux first; with an unlimited disk there is no saturation;
///   * viscous friction enters xi1 through omega_decay (1 in the paper);
///   * an optional reaching law S_{k+1} = lambda S_k per channel (lambda = 0 is the paper's
///     deadbeat law S_{k+1} = 0), so that a board with a quantized encoder is not driven
///     bang-bang by measurement noise.
#include <cmath>
#include <limits>

#include "control/voltage_fed_model.hpp"
#include "control/frames.hpp"
#include "control/input_disk.hpp"

namespace imd::control {

struct DsmcConfig {
  /// B_k is refused (singular) when |det B_k| is below its value for a pure magnetizing state
  /// at this squared flux: det B_k ~ 2 b1 eta2 a11 |Phi~|^2.
  double min_flux2_Wb2 = 1e-3;
  /// Reaching laws e_{k+1} = pole e_k of the speed and squared-flux errors, in [0, 1).
  double speed_reaching_pole = 0.0;
  double flux_reaching_pole = 0.0;
};

template <typename T>
struct DsmcInput {
  Vec2<T> flux_r_AB_Wb = Vec2<T>::Zero();  ///< rotor flux (estimate), rotor frame
  Vec2<T> i_s_AB_A = Vec2<T>::Zero();      ///< stator current, rotor frame
  T omega_mech_rad_s = T(0);               ///< speed (estimate)
  T load_Nm = T(0);                        ///< load torque C_L (estimate)
  T omega_ref_rad_s = T(0);                ///< speed reference at k (for the reaching law)
  T omega_ref_next_rad_s = T(0);           ///< speed reference at k+1
  T flux2_ref_Wb2 = T(0);                  ///< squared flux reference at k (reaching law)
  T flux2_ref_next_Wb2 = T(0);             ///< squared flux reference at k+1
  InputDisk<T> feasible;                   ///< inputs v~ the limits allow
};

enum class DsmcStatus { ok, singular };

template <typename T>
struct DsmcOutput {
  DsmcStatus status = DsmcStatus::singular;
  Vec2<T> v_AB_V = Vec2<T>::Zero();  ///< v~_k to apply (zero if singular)
  T w_alpha = T(0), w_beta = T(0);   ///< applied transformed controls
  T w_eq_alpha = T(0);               ///< speed equivalent control before saturation
  T w_beta_tilde = T(0);             ///< flux control before saturation, (12)
  T discriminant = T(0);             ///< b_k^2 - 4 a_k c_k
  T c_k = T(0);
  T det_B = T(0);
  bool speed_saturated = false;
  bool flux_saturated = false;
};

template <typename T>
class Dsmc {
 public:
  Dsmc(const VoltageFedCoefficients& c, const DsmcConfig& config) noexcept
      : a11_(T(c.a11)),
        a12_(T(c.a12)),
        b1_(T(c.b1)),
        eta1_(T(c.eta1)),
        eta2_(T(c.eta2)),
        eta3_(T(c.eta3)),
        omega_decay_(T(c.omega_decay)),
        load_to_omega_(T(c.load_to_omega)),
        min_det_(T(std::abs(2.0 * c.b1 * c.eta2 * c.a11) * config.min_flux2_Wb2)),
        speed_pole_(T(config.speed_reaching_pole)),
        flux_pole_(T(config.flux_reaching_pole)) {}

  /// One step of the law. Tick context.
  DsmcOutput<T> step(const DsmcInput<T>& in) const noexcept {
    DsmcOutput<T> out;
    const Vec2<T>& flux = in.flux_r_AB_Wb;
    const Vec2<T>& current = in.i_s_AB_A;
    // (7): lambda1^T v = (eta2 Phi + eta3 I)^T J v, i.e. lambda1 = -J (eta2 Phi + eta3 I).
    const Vec2<T> g = eta2_ * flux + eta3_ * current;
    const Vec2<T> lambda1 = -J_times(g);
    const Vec2<T> m = a11_ * flux + a12_ * current;  // flux at k+1 without input
    const Vec2<T> lambda2 = (T(2) * b1_) * m;
    const T xi1 = omega_decay_ * in.omega_mech_rad_s + eta1_ * dot_J(current, flux);
    const T xi2 = m.squaredNorm();
    // det [lambda1^T; lambda2^T] = g . lambda2.
    const T det = g.dot(lambda2);
    out.det_B = det;
    if (!(std::abs(det) >= min_det_)) return out;  // also refuses NaN
    out.status = DsmcStatus::ok;

    // Targets of the next step: the reference plus what the reaching law leaves of the error.
    const T omega_target =
        in.omega_ref_next_rad_s + speed_pole_ * (in.omega_mech_rad_s - in.omega_ref_rad_s);
    const T flux2_target =
        in.flux2_ref_next_Wb2 + flux_pole_ * (flux.squaredNorm() - in.flux2_ref_Wb2);
    out.w_eq_alpha = omega_target - xi1 - load_to_omega_ * in.load_Nm;
    const T lambda11 = lambda1.squaredNorm(), lambda22 = lambda2.squaredNorm();
    const T lambda12 = lambda1.dot(lambda2);
    const T b1_over_det2 = b1_ * b1_ / (det * det);
    const auto flux_control = [&](T w_alpha, DsmcOutput<T>& o) {
      const T a = b1_over_det2 * lambda11;
      const T b = T(1) - T(2) * b1_over_det2 * w_alpha * lambda12;
      const T c = xi2 - flux2_target + b1_over_det2 * w_alpha * w_alpha * lambda22;
      o.c_k = c;
      o.discriminant = b * b - T(4) * a * c;
      return o.discriminant >= T(0) ? stable_root(a, b, c, o.discriminant) : -b / (T(2) * a);
    };

    T w_alpha = out.w_eq_alpha;
    T w_beta = flux_control(w_alpha, out);
    out.w_beta_tilde = w_beta;
    if (!in.feasible.unlimited()) {
      // Flux channel first: its bound is the range of lambda2^T v~ over the disk; the speed
      // channel gets the range of lambda1^T v~ on the chord the flux control leaves. A
      // saturated speed channel changes the flux control (through b_k and c_k: a large w_alpha
      // costs flux), so it is solved again once; the final pass sets the flags.
      for (int pass = 0; pass < 2; ++pass) {
        const Interval beta = range_over_disk(lambda2, in.feasible);
        out.w_beta_tilde = w_beta;
        out.flux_saturated = !beta.contains(w_beta);
        w_beta = beta.clamp(w_beta);
        const Interval alpha = range_on_chord(lambda1, lambda2, w_beta, in.feasible);
        out.speed_saturated = !alpha.contains(out.w_eq_alpha);
        w_alpha = alpha.clamp(out.w_eq_alpha);
        // The final w_alpha is clamped on the chord of the final w_beta, which was solved for
        // the pass-0 w_alpha: the flux misses by at most b1^2 |v~|^2 (~6e-8 Wb^2 at 300 V).
        if (pass == 0 && out.speed_saturated) {
          w_beta = flux_control(w_alpha, out);
        } else {
          break;
        }
      }
    }
    out.w_alpha = w_alpha;
    out.w_beta = w_beta;
    // v~ = B^{-1} w = (-w_alpha J lambda2 + w_beta J lambda1) / det.
    out.v_AB_V = (J_times<T>(lambda1) * w_beta - J_times<T>(lambda2) * w_alpha) / det;
    return out;
  }

 private:
  struct Interval {
    T low, high;
    bool contains(T x) const noexcept { return x >= low && x <= high; }
    T clamp(T x) const noexcept { return x < low ? low : (x > high ? high : x); }
  };

  /// Root (11), -b + sqrt(D) over 2a, without cancellation: for b >= 0 it equals
  /// -2c / (b + sqrt(D)); for b < 0 the paper's form does not cancel.
  static T stable_root(T a, T b, T c, T discriminant) noexcept {
    using std::sqrt;
    const T root = sqrt(discriminant);
    return b >= T(0) ? T(-2) * c / (b + root) : (root - b) / (T(2) * a);
  }

  /// Range of l^T v over the disk: l^T centre -/+ radius |l|.
  static Interval range_over_disk(const Vec2<T>& l, const InputDisk<T>& disk) noexcept {
    const T middle = l.dot(disk.center_V), half = disk.radius_V * l.norm();
    return {middle - half, middle + half};
  }

  /// Range of l1^T v over the chord {v in disk : l2^T v = w_beta}; a single point if the line
  /// misses the disk (then the nearest point of the line is used).
  static Interval range_on_chord(const Vec2<T>& l1, const Vec2<T>& l2, T w_beta,
                                 const InputDisk<T>& disk) noexcept {
    using std::sqrt;
    const T l2_norm2 = l2.squaredNorm();
    const T offset = (w_beta - l2.dot(disk.center_V)) / l2_norm2;
    const Vec2<T> foot = disk.center_V + offset * l2;
    const T h2 = offset * offset * l2_norm2;
    const T r2 = disk.radius_V * disk.radius_V;
    const T half_chord = h2 < r2 ? sqrt(r2 - h2) : T(0);
    const T slope = std::abs(l1.dot(J_times<T>(l2))) / sqrt(l2_norm2);
    const T middle = l1.dot(foot);
    return {middle - half_chord * slope, middle + half_chord * slope};
  }

  T a11_, a12_, b1_, eta1_, eta2_, eta3_, omega_decay_, load_to_omega_;
  T min_det_;
  T speed_pole_, flux_pole_;
};

}  // namespace imd::control
