#pragma once
/// Input-output linearizing control of torque and stator flux for the current-fed motor,
/// paper 001, Section 4. With x = (phi_sA, phi_sB, i_A, i_B) at t_k (the current held over the
/// period) and u = i(t_{k+1}), the outputs (20) obey (22)-(23):
///   y1(k+1) = b11 u1 + b12 u2,        (torque, k_T = 3/2 included: amplitude-invariant Clarke)
///   y2(k+1) = a + b21 u1 + b22 u2,    (the modified squared stator flux)
/// with phi_r = e^{-eta T0} phi_s + ls (1 - sigma - e^{-eta T0}) i (the paper's phi-bar_r),
/// a = ls (1 - sigma - e^{-eta T0}) phi_s^T i, B = [[-k n_p phi_r2, k n_p phi_r1],
/// [ls sigma phi_s1, ls sigma phi_s2]] and det B = -k n_p ls sigma phi_s^T phi_r (26). The law
/// (24) u = B^-1 [v1; v2 - a] gives y1(k+1) = v1, y2(k+1) = v2 (25).
///
/// Determinant guard (docs/iol.md): B must stay invertible with det B < 0, i.e. the stator flux
/// and phi_r must not become orthogonal. Following the paper's suggestion the torque command
/// v1 is saturated dynamically: the largest |v1| <= |v1_ref| is used for which the exactly
/// predicted fluxes of step k+1 stay within max_angle of each other. A state whose own B_k is
/// (nearly) singular, a flux command that breaks the guard even without torque, and non-finite
/// inputs are refused: the current is held.
///
/// Reach (docs/iol.md, "At the voltage limit"): on a voltage inverter the current loop makes
/// the step to u from the held current, and a u outside the currents it reaches before the law
/// steps again (control/current_reach.hpp) does not arrive. Such a u is cut to that disk with the
/// torque given up first: to the point of the disk on the second output's line (y2(k+1) = v2
/// is a line in u) whose torque is nearest v1, or, where that line misses the disk, to the
/// disk's point nearest the line. A cut that would break the determinant guard is not made.
/// Tick context; no division by zero.
#include <algorithm>
#include <cmath>

#include "control/current_fed_model.hpp"
#include "control/current_reach.hpp"
#include "control/frames.hpp"
#include "control/real.hpp"

namespace imd::control {

struct IolConfig {
  /// Largest angle between the stator flux and phi_r at step k+1: det B(k+1) stays below
  /// -cos(max_angle) of its value for aligned vectors (cos 60 deg = 0.5).
  Real max_angle_rad = Real(1.0471975511965976);
  /// B_k is refused when the angle at step k exceeds this (det within cos of zero) or the
  /// stator flux is below min_flux_Wb.
  Real refuse_angle_rad = Real(1.5184364492350666);  // 87 degrees
  Real min_flux_Wb = Real(1e-3);
};

enum class IolStatus { ok, singular };

template <typename T>
struct IolInput {
  Vec2<T> flux_s_AB_Wb = Vec2<T>::Zero();  ///< x1, x2 at t_k
  Vec2<T> i_s_AB_A = Vec2<T>::Zero();      ///< x3, x4: the current held over [t_k, t_{k+1})
  T torque_ref_Nm = T(0);                  ///< v1, the torque wanted at t_{k+1}
  T y2_ref = T(0);                         ///< v2, the second output wanted at t_{k+1} (Wb^2)
  /// The currents the current loop reaches at t_{k+1}; unlimited for a current source.
  CurrentDisk<T> reach;
};

template <typename T>
struct IolOutput {
  IolStatus status = IolStatus::singular;
  Vec2<T> i_next_AB_A = Vec2<T>::Zero();  ///< u = i(t_{k+1}): the current for the next period
  T torque_cmd_Nm = T(0);                 ///< v1 after the guard
  bool torque_limited = false;            ///< v1 cut, by the guard or by the reach
  bool reach_limited = false;             ///< u cut to the reachable currents
  T det_B = T(0);                         ///< det B_k
  T det_B_next = T(0);                    ///< predicted det B_{k+1}
};

template <typename T>
class Iol {
 public:
  Iol(const CurrentFedCoefficients& c, const IolConfig& config) noexcept
      : e_(T(c.flux_decay)),
        c_(T(c.flux_from_i_now_H)),
        ls_sigma_(T(c.flux_from_i_next_H)),
        k_np_(T(c.torque_per_flux_A)),
        cos_max_(T(std::cos(config.max_angle_rad))),
        cos_refuse_(T(std::cos(config.refuse_angle_rad))),
        min_flux_(T(config.min_flux_Wb)) {}

  /// The paper's phi-bar_r(k) = e^{-eta T0} phi_s + ls (1 - sigma - e^{-eta T0}) i.
  Vec2<T> modified_rotor_flux(const Vec2<T>& flux_s, const Vec2<T>& i) const noexcept {
    return e_ * flux_s + c_ * i;
  }

  /// y2(k) of (20) from the stator fluxes of steps k and k-1.
  T y2(const Vec2<T>& flux_s_now, const Vec2<T>& flux_s_before) const noexcept {
    return flux_s_now.dot(flux_s_before) - e_ * flux_s_before.squaredNorm();
  }

  IolOutput<T> step(const IolInput<T>& in) const noexcept {
    IolOutput<T> out;
    out.i_next_AB_A = in.i_s_AB_A;  // refused: hold the current
    const Vec2<T>& flux = in.flux_s_AB_Wb;
    const Vec2<T> flux_r = modified_rotor_flux(flux, in.i_s_AB_A);
    out.det_B = -k_np_ * ls_sigma_ * flux.dot(flux_r);
    if (!aligned_enough(flux, flux_r, cos_refuse_) || !(flux.norm() >= min_flux_)) return out;
    if (!std::isfinite(in.torque_ref_Nm) || !std::isfinite(in.y2_ref) || !in.i_s_AB_A.allFinite()) {
      return out;
    }

    const T a = c_ * flux.dot(in.i_s_AB_A);
    const auto law = [&](T v1) {  // (24): u = B^-1 [v1; v2 - a]
      const T w2 = in.y2_ref - a;
      // B^-1 = [[b22, -b12], [-b21, b11]] / det
      const T b11 = -k_np_ * flux_r.y(), b12 = k_np_ * flux_r.x();
      const T b21 = ls_sigma_ * flux.x(), b22 = ls_sigma_ * flux.y();
      return Vec2<T>((b22 * v1 - b12 * w2) / out.det_B, (-b21 * v1 + b11 * w2) / out.det_B);
    };
    const auto next_fluxes_ok = [&](const Vec2<T>& u, T* det_next) {
      const Vec2<T> flux_next = e_ * flux + c_ * in.i_s_AB_A + ls_sigma_ * u;  // (19)
      const Vec2<T> flux_r_next = modified_rotor_flux(flux_next, u);
      *det_next = -k_np_ * ls_sigma_ * flux_next.dot(flux_r_next);
      return aligned_enough(flux_next, flux_r_next, cos_max_);
    };

    // The flux-only command (v1 = 0) must itself keep B invertible; if the flux command alone
    // turns the stator flux away from phi_r (v2 <= -e F), no torque saturation can help.
    T det_flux_only;
    if (!next_fluxes_ok(law(T(0)), &det_flux_only)) return out;
    out.status = IolStatus::ok;
    Vec2<T> u = law(in.torque_ref_Nm);
    out.torque_cmd_Nm = in.torque_ref_Nm;
    if (!next_fluxes_ok(u, &out.det_B_next)) {
      // Largest fraction s of v1_ref that keeps the guard (bisection; s = 0 is the flux-only
      // command, which keeps the fluxes as aligned as the flux command allows).
      T low = T(0), high = T(1);
      for (int i = 0; i < 30; ++i) {
        const T mid = (low + high) / T(2);
        T ignored;
        (next_fluxes_ok(law(mid * in.torque_ref_Nm), &ignored) ? low : high) = mid;
      }
      out.torque_cmd_Nm = low * in.torque_ref_Nm;
      out.torque_limited = true;
      u = law(out.torque_cmd_Nm);
      next_fluxes_ok(u, &out.det_B_next);
    }
    if (!in.reach.contains(u)) {
      // The second output's line n . u = w2 with n = (b21, b22) = ls sigma phi_s (24).
      const Vec2<T> n = ls_sigma_ * flux;
      const T w2 = in.y2_ref - a;
      const Vec2<T> foot =
          in.reach.center_A + ((w2 - n.dot(in.reach.center_A)) / n.squaredNorm()) * n;
      const Vec2<T> to_line = foot - in.reach.center_A;
      const T distance2 = to_line.squaredNorm(), radius2 = in.reach.radius_A * in.reach.radius_A;
      Vec2<T> cut;
      if (distance2 <= radius2) {  // the chord: u's place on the line, clamped to it
        const Vec2<T> along = J_times<T>(n) / n.norm();
        const T half_chord = std::sqrt(radius2 - distance2);
        cut = foot + std::clamp(along.dot(u - foot), -half_chord, half_chord) * along;
      } else {
        cut = in.reach.center_A + (in.reach.radius_A / std::sqrt(distance2)) * to_line;
      }
      T det_next;
      if (next_fluxes_ok(cut, &det_next)) {
        u = cut;
        out.det_B_next = det_next;
        out.torque_cmd_Nm = k_np_ * (flux_r.x() * u.y() - flux_r.y() * u.x());  // b1 . u
        out.torque_limited = out.reach_limited = true;
      }
    }
    out.i_next_AB_A = u;
    return out;
  }

 private:
  /// a . b >= cos_limit |a| |b|, false for NaN.
  static bool aligned_enough(const Vec2<T>& a, const Vec2<T>& b, T cos_limit) noexcept {
    return a.dot(b) >= cos_limit * a.norm() * b.norm() && a.dot(b) > T(0);
  }

  T e_, c_, ls_sigma_, k_np_;
  T cos_max_, cos_refuse_, min_flux_;
};

}  // namespace imd::control
