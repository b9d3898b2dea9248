#pragma once
/// The set of rotor-frame inputs v~ that respect the inverter voltage limit and the motor current
/// limit over the next period, approximated by one disk (docs/control.md, "Bounds").
///
/// * Voltage: the stator voltage in the rotor frame is u_AB = sigma p w J (I~ + beta Phi~) + v~
///   (feedback (2); rotations commute with J), and SVPWM reaches |u| <= v_max_V. So v~ lies in
///   the disk centred at -sigma p w J (I~ + beta Phi~) with radius v_max_V.
/// * Current: I~_{k+1} = a21 Phi~ + a22 I~ + b2 v~ must satisfy |I~_{k+1}| <= i_max_A, the disk
///   centred at -(a21 Phi~ + a22 I~)/b2 with radius i_max_A / b2.
/// The feasible set is their intersection, a lens; the controller uses the largest disk inside
/// it. All functions run in tick context.
#include <algorithm>
#include <cmath>
#include <limits>

#include "control/frames.hpp"

namespace imd::control {

template <typename T>
struct InputDisk {
  Vec2<T> center_V = Vec2<T>::Zero();
  T radius_V = std::numeric_limits<T>::infinity();  ///< infinite: no limit

  /// Only +inf means no limit; a NaN radius (a broken input) allows nothing but the centre.
  bool unlimited() const noexcept { return radius_V == std::numeric_limits<T>::infinity(); }
  bool contains(const Vec2<T>& v_V, T tolerance_V = T(0)) const noexcept {
    // Squared: no square root. A negative or NaN bound contains nothing, as |v - c| <= it.
    const T bound_V = radius_V + tolerance_V;
    return unlimited() || (bound_V >= T(0) && (v_V - center_V).squaredNorm() <= bound_V * bound_V);
  }
  /// The nearest point of the disk.
  Vec2<T> clamp(const Vec2<T>& v_V) const noexcept {
    if (unlimited()) return v_V;
    const Vec2<T> offset = v_V - center_V;
    const T distance = offset.norm();
    if (distance <= radius_V) return v_V;
    if (!(radius_V > T(0))) return center_V;  // zero or NaN radius
    return center_V + offset * (radius_V / distance);
  }
};

/// Largest disk inside the intersection of two disks. If they do not intersect, returns the
/// point of `first` nearest to `second` (radius 0): `first` is the hard limit. Inlined: the
/// disks it takes and gives then stay in registers (docs/performance-compiler.md).
template <typename T>
[[gnu::always_inline]] inline InputDisk<T> inscribed_disk(const InputDisk<T>& first,
                                                          const InputDisk<T>& second) noexcept {
  if (second.unlimited()) return first;
  if (first.unlimited()) return second;
  const Vec2<T> axis = second.center_V - first.center_V;
  const T s = axis.norm();
  if (s + second.radius_V <= first.radius_V) return second;  // second inside first
  if (s + first.radius_V <= second.radius_V) return first;   // first inside second
  const Vec2<T> unit = axis * (T(1) / s);                    // s > 0 here
  if (s >= first.radius_V + second.radius_V) return {first.center_V + unit * first.radius_V, T(0)};
  // The lens meets the axis on [s - r2, r1] (measured from first's centre); the largest disk
  // touching both arcs there has its centre at r1 - rho with rho = (r1 + r2 - s) / 2.
  const T rho = (first.radius_V + second.radius_V - s) / T(2);
  return {first.center_V + unit * (first.radius_V - rho), rho};
}

}  // namespace imd::control
