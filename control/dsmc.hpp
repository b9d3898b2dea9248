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
///     bang-bang by measurement noise;
///   * the speed channel through the torque (DsmcSpeedChannel::torque, the default): w_alpha
///     sets the torque product y = I^T J Phi of step k+1, which the exact model makes affine
///     in v~ (the v~^T J v~ term vanishes), and the speed reaches its reference through it,
///     e_{k+2} = pole e_{k+1}. The paper's channel sets w_{k+1} directly and so cancels the
///     sampled system's zero near -1: the q current rings at half the sample rate
///     (docs/control.md). DsmcSpeedChannel::paper keeps it, to reproduce the paper.
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>

#include "control/frames.hpp"
#include "control/input_disk.hpp"
#include "control/real.hpp"
#include "control/voltage_fed_model.hpp"

namespace imd::control {

enum class DsmcSpeedChannel : uint8_t {
  torque,  ///< the speed through the torque of the next step (no ringing)
  paper,   ///< the speed of the next step directly, Section III (cancels the zero near -1)
};

struct DsmcConfig {
  /// B_k is refused (singular) when |det B_k| is below its value for a pure magnetizing state
  /// at this squared flux: det B_k ~ 2 b1 eta2 a11 |Phi~|^2.
  Real min_flux2_Wb2 = Real(1e-3);
  /// Reaching laws e_{k+1} = pole e_k of the speed and squared-flux errors, in [0, 1).
  Real speed_reaching_pole = 0.0;
  Real flux_reaching_pole = 0.0;
  DsmcSpeedChannel speed_channel = DsmcSpeedChannel::paper;
  /// The torque channel's current pole: the torque and the flux's current approach their
  /// targets as e_{k+1} = pole e_k (0: deadbeat, which passes the current's noise at
  /// sigma Ls / delta volts per ampere).
  Real current_pole = 0.0;
  /// The torque channel's largest |I^T J Phi| (the torque limit over 3/2 p Lm/Lr), A Wb.
  Real torque_product_limit_AWb = std::numeric_limits<Real>::max();
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
  bool torque_clamped = false;  ///< torque channel: the torque limit cut its torque
};

template <typename T>
class Dsmc {
 public:
  Dsmc(const VoltageFedCoefficients& c, const DsmcConfig& config) noexcept
      : a11_(T(c.a11)),
        a12_(T(c.a12)),
        a21_(T(c.a21)),
        a22_(T(c.a22)),
        b1_(T(c.b1)),
        b2_(T(c.b2)),
        eta1_(T(c.eta1)),
        eta2_(T(c.eta2)),
        eta3_(T(c.eta3)),
        omega_decay_(T(c.omega_decay)),
        load_to_omega_(T(c.load_to_omega)),
        min_det_(T(std::abs(2 * c.b1 * c.eta2 * c.a11) * config.min_flux2_Wb2)),
        speed_pole_(T(config.speed_reaching_pole)),
        flux_pole_(T(config.flux_reaching_pole)),
        torque_channel_(config.speed_channel == DsmcSpeedChannel::torque),
        current_pole_(T(config.current_pole)),
        y_limit_(T(std::min(config.torque_product_limit_AWb, Real(1e30)))) {
    // Through the current, det B_k ~ 2 q b2 a11^3 |Phi~|^2: its floor scales alike.
    if (torque_channel_) {
      const Real q = c.a12 * c.b2 + c.a11 * c.b1;
      min_det_ = T(std::abs(2 * q * c.b2 * c.a11 * c.a11 * c.a11) * config.min_flux2_Wb2);
    }
  }

  /// One step of the law. Tick context. Inlined into its caller, the law stage's adapter: its
  /// input and output structures then stay in registers (docs/performance-compiler.md).
  [[gnu::always_inline]] DsmcOutput<T> step(const DsmcInput<T>& in) const noexcept {
    DsmcOutput<T> out;
    const Vec2<T>& flux = in.flux_r_AB_Wb;
    const Vec2<T>& current = in.i_s_AB_A;
    const Vec2<T> m = a11_ * flux + a12_ * current;  // flux at k+1 without input
    const Vec2<T> n = a21_ * flux + a22_ * current;  // current at k+1 without input
    // The speed row: the paper's (7), lambda1^T v = (eta2 Phi + eta3 I)^T J v; through the
    // torque, y_{k+1} = (n + b2 v)^T J (m + b1 v) = n^T J m + (b1 n - b2 m)^T J v. Either way
    // lambda1 = -J g.
    const Vec2<T> g = torque_channel_ ? Vec2<T>(b1_ * n - b2_ * m)
                                      : Vec2<T>(eta2_ * flux + eta3_ * current);
    const Vec2<T> lambda1 = -J_times(g);
    // The flux row: the paper's |Phi_{k+1}|^2 = |m + b1 v|^2; through the current, the flux
    // one step later, |Phi_{k+2}|^2 = |p + q v|^2 with p = a11 m + a12 n, q = a11 b1 + a12 b2
    // (the next input's own b1 share left out). Either way |base + gain v|^2.
    const T gain = torque_channel_ ? a11_ * b1_ + a12_ * b2_ : b1_;
    const Vec2<T> base = torque_channel_ ? Vec2<T>(a11_ * m + a12_ * n) : m;
    const Vec2<T> lambda2 = (T(2) * gain) * base;
    const T xi1 = omega_decay_ * in.omega_mech_rad_s + eta1_ * dot_J(current, flux);
    const T xi2 = base.squaredNorm();
    // det [lambda1^T; lambda2^T] = g . lambda2.
    const T det = g.dot(lambda2);
    out.det_B = det;
    if (!(std::abs(det) >= min_det_)) return out;  // also refuses NaN
    out.status = DsmcStatus::ok;

    // Targets of the next step: the reference plus what the reaching law leaves of the error.
    const T omega_target =
        in.omega_ref_next_rad_s + speed_pole_ * (in.omega_mech_rad_s - in.omega_ref_rad_s);
    const T flux2_target =
        torque_channel_
            ? T(2) * in.flux2_ref_next_Wb2 - in.flux2_ref_Wb2 +
                  flux_pole_ * (m.squaredNorm() - in.flux2_ref_next_Wb2)
            : in.flux2_ref_next_Wb2 + flux_pole_ * (flux.squaredNorm() - in.flux2_ref_Wb2);
    out.w_eq_alpha = omega_target - xi1 - load_to_omega_ * in.load_Nm;
    if (torque_channel_) {
      // w_{k+1} ~ xi1 + load term (v~'s own share, eta2 and eta3, is 1e-3 of it), and
      // w_{k+2} = decay w_{k+1} + eta1 y_{k+1} + load term: the torque that puts w_{k+2} on
      // its reference with the error e_{k+2} = pole e_{k+1}. The reference at k+2 is
      // extrapolated from k and k+1 (exact on ramps).
      const T omega_next = xi1 + load_to_omega_ * in.load_Nm;
      const T omega_ref_after = T(2) * in.omega_ref_next_rad_s - in.omega_ref_rad_s;
      const T target = omega_ref_after + speed_pole_ * (omega_next - in.omega_ref_next_rad_s);
      const T y_ref =
          (target - omega_decay_ * omega_next - load_to_omega_ * in.load_Nm) * per_eta1_;
      // The torque approaches it: y_{k+1} - y* = current_pole (y_k - y*).
      const T y_now = dot_J(current, flux), y_target = std::clamp(y_ref, -y_limit_, y_limit_);
      out.torque_clamped = y_target != y_ref;
      out.w_eq_alpha = y_target + current_pole_ * (y_now - y_target) - dot_J(n, m);
    }
    const T lambda11 = lambda1.squaredNorm(), lambda22 = lambda2.squaredNorm();
    const T lambda12 = lambda1.dot(lambda2);
    const T per_det = T(1) / det;  // the one division: B^{-1} and b1^2 / det^2 multiply by it
    const T b1_over_det2 = (gain * per_det) * (gain * per_det);
    // Through the current, the flux's correction is taken at the current pole's pace too:
    // measured from the flux the present current would give (held over the next period), a
    // share current_pole of the correction is left to the next step.
    const T flux2_aim =
        torque_channel_
            ? flux2_target + current_pole_ * ((a11_ * m + a12_ * current).squaredNorm() -
                                              flux2_target)
            : flux2_target;
    const auto flux_control = [&](T w_alpha, DsmcOutput<T>& o) {
      const T a = b1_over_det2 * lambda11;
      const T b = T(1) - T(2) * b1_over_det2 * w_alpha * lambda12;
      const T c = xi2 - flux2_aim + b1_over_det2 * w_alpha * w_alpha * lambda22;
      o.c_k = c;
      o.discriminant = b * b - T(4) * a * c;
      return o.discriminant >= T(0) ? stable_root(a, b, c, o.discriminant) : -b / (T(2) * a);
    };

    T w_alpha = out.w_eq_alpha;
    T w_beta = flux_control(w_alpha, out);
    out.w_beta_tilde = w_beta;
    // v~ = B^{-1} w = (-w_alpha J lambda2 + w_beta J lambda1) / det.
    const auto input = [&](T wa, T wb) {
      return Vec2<T>((J_times<T>(lambda1) * wb - J_times<T>(lambda2) * wa) * per_det);
    };
    out.v_AB_V = input(w_alpha, w_beta);
    // Most ticks the solution lies well inside the disk, and neither channel can saturate:
    // the ranges below (two square roots, a division) are computed only within a thousandth
    // of the radius of its edge, where the clamps may act. Inside by 1e-3 r, w_beta = l2^T v
    // lies inside its range by about 1e-3 r |l2| and w_alpha = l1^T v inside its range on the
    // chord by about 1e-3 r |l1 x l2| / |l2|: for a well-conditioned B far above the rounding
    // of v, so the clamps would leave w as it is. A zero, negative or NaN radius contains
    // nothing; the whole plane contains everything.
    if (in.feasible.contains(out.v_AB_V, T(-1e-3) * in.feasible.radius_V)) {
      out.w_alpha = w_alpha;
      out.w_beta = w_beta;
      return out;
    }
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
    out.w_alpha = w_alpha;
    out.w_beta = w_beta;
    out.v_AB_V = input(w_alpha, w_beta);
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

  T a11_, a12_, a21_, a22_, b1_, b2_, eta1_, eta2_, eta3_, omega_decay_, load_to_omega_;
  T min_det_;
  T speed_pole_, flux_pole_;
  bool torque_channel_;
  T current_pole_;
  T y_limit_;
  T per_eta1_ = T(1) / eta1_;  ///< the torque target multiplies by it (after eta1_)
};

}  // namespace imd::control
