#include "firmware/identification/standstill_identifier.hpp"

#include <algorithm>

namespace imd::firmware {

template <typename T>
void StandstillIdentifier<T>::enter(IdentificationStep s) noexcept {
  step_ = s;
  ticks_ = 0;
  settle_ = SettlingDetector<T>{};
  window_v_.reset();
  window_fill_ = 0;
  arrived_ = true;
  holding_ = false;
  hold_ = Level{};
}

template <typename T>
control::Vec2<T> StandstillIdentifier<T>::current_loop(const Vec2& i_A, T i_ref_alpha_A) noexcept {
  // PI per axis, the integral clamped with the output (no wind-up at the limit).
  const Vec2 error(i_ref_alpha_A - i_A.x(), -i_A.y());
  integral_V_ += ki_T_ * error;
  Vec2 u = kp_ * error + integral_V_;
  const T magnitude = u.norm();
  if (magnitude > v_limit_V_) {
    u *= v_limit_V_ / magnitude;
    integral_V_ = u - kp_ * error;
    ++saturated_ticks_;
  } else {
    saturated_ticks_ = 0;
  }
  return u;
}

template <typename T>
bool StandstillIdentifier<T>::level(const Vec2& i_A, T v_acting_V, T i_ref_A, T i_from_A) noexcept {
  if (holding_) {
    hold_.v_V.add(v_acting_V);
    hold_.i_A.add(i_A.x());
    return ++hold_.ticks >= hold_.hold_ticks;
  }
  window_v_.add(v_acting_V);
  // The current has arrived once within 5 % of the step of its reference (the PI's own modes
  // have died out; what is left of the voltage's decay is the rotor's).
  if (std::abs(i_A.x() - i_ref_A) > T(0.05) * std::abs(i_ref_A - i_from_A)) arrived_ = false;
  if (++window_fill_ < window_ticks_) return false;
  const T mean = window_v_.value() / T(window_fill_);
  window_v_.reset();
  window_fill_ = 0;
  const bool arrived = arrived_;
  arrived_ = true;  // judged again over the next window
  if (settle_.on_window(mean, arrived)) {
    // Hold as long as the settling took (at least 4 windows): the level's mean then carries
    // noise of the same order as the transient's sums (docs/identification.md).
    holding_ = true;
    hold_.hold_ticks = std::max<uint32_t>(4, settle_.windows()) * uint32_t(window_ticks_);
  }
  return false;
}

template <typename T>
control::Vec2<T> StandstillIdentifier<T>::step(const Vec2& i_A) noexcept {
  u_acting_V_ = u_written_V_;  // written last tick, acting over this period
  ++ticks_;
  ++ticks_in_[int(step_)];
  Vec2 u = Vec2::Zero();
  switch (step_) {
    case IdentificationStep::low_level:
      u = current_loop(i_A, i_low_A_);
      if (level(i_A, u_acting_V_.x(), i_low_A_, T(0))) {
        v_low_V_ = hold_.v_V.value() / T(hold_.ticks);
        i_low_meas_A_ = hold_.i_A.value() / T(hold_.ticks);
        enter(IdentificationStep::high_level);
      }
      break;
    case IdentificationStep::high_level: {
      u = current_loop(i_A, i_high_A_);
      // Moments from the step until settled (not over the hold: their error from the level's
      // noise grows with the square of their length): the voltage over [t_k, t_k+1] at its
      // mid-period time, the current sampled at t_k (k counts from the tick of the step).
      const T t_s = T(ticks_ - 1) * period_s_;
      const T v = u_acting_V_.x();
      if (!holding_) {
        sv_.add(v * period_s_);
        stv_.add((t_s + T(0.5) * period_s_) * v * period_s_);
        si_.add(i_A.x() * period_s_);
        sti_.add(t_s * i_A.x() * period_s_);
        k0_.add(period_s_);
        k1v_.add((t_s + T(0.5) * period_s_) * period_s_);
        k1i_.add(t_s * period_s_);
      }
      if (level(i_A, v, i_high_A_, i_low_A_)) {
        v_high_V_ = hold_.v_V.value() / T(hold_.ticks);
        i_high_meas_A_ = hold_.i_A.value() / T(hold_.ticks);
        hf_bias_V_ = integral_V_.x();
        i_previous_A_ = i_A.x();
        enter(IdentificationStep::transient_inductance);
      }
      break;
    }
    case IdentificationStep::transient_inductance: {
      // The loop is frozen at its bias; the square wave alone moves the current. The current
      // step over the last period pairs with the square wave's value acting over it.
      const T di = i_A.x() - i_previous_A_;
      i_previous_A_ = i_A.x();
      if (ticks_ > 1) {
        sdd_.add(delta_acting_V_ * delta_acting_V_);
        sdi_.add(delta_acting_V_ * di);
      }
      delta_acting_V_ = delta_written_V_;
      // Two periods at a quarter of the amplitude probe sigma Ls; then the amplitude is cut to
      // the planned ripple on the probed value, and the sums start again.
      const auto probe_ticks = uint32_t(4 * hf_half_);
      if (ticks_ == probe_ticks + 1 && sdi_.value() > T(0)) {
        const T sigma_Ls_H = period_s_ * sdd_.value() / sdi_.value();
        hf_V_ = std::min(hf_V_, hf_ripple_A_ * sigma_Ls_H / (T(hf_half_) * period_s_));
        sdd_.reset();
        sdi_.reset();
      }
      const T amplitude_V = ticks_ <= probe_ticks ? T(0.25) * hf_V_ : hf_V_;
      const int half = int((ticks_ - 1) / uint32_t(hf_half_));
      delta_written_V_ = (half % 2 == 0 ? T(1) : T(-1)) * amplitude_V;
      if (int(ticks_) > hf_ticks_) delta_written_V_ = T(0);
      u = Vec2(hf_bias_V_ + delta_written_V_, integral_V_.y());
      if (int(ticks_) > hf_ticks_ + 2) {  // the last square-wave value has acted
        ramp_from_A_ = i_A.x();
        integral_V_.x() = hf_bias_V_;
        enter(IdentificationStep::ramp_down);
      }
      break;
    }
    case IdentificationStep::ramp_down: {
      const T share = T(1) - std::min(T(1), T(ticks_) / T(ramp_ticks_));
      u = current_loop(i_A, ramp_from_A_ * share);
      if (ticks_ >= ramp_ticks_) {
        u = Vec2::Zero();
        finish();
      }
      break;
    }
    case IdentificationStep::done:
    case IdentificationStep::failed:
      break;
  }
  if (!finished()) {
    const bool level_step =
        step_ == IdentificationStep::low_level || step_ == IdentificationStep::high_level;
    if (level_step && ticks_ > max_level_ticks_) fail(IdentificationFailure::not_settled);
    if (saturated_ticks_ > window_ticks_) fail(IdentificationFailure::voltage_limit);
  }
  if (finished()) u = Vec2::Zero();
  u_written_V_ = u;
  return u;
}

template <typename T>
void StandstillIdentifier<T>::finish() noexcept {
  StandstillResult<T> r;
  const T delta_i_A = i_high_meas_A_ - i_low_meas_A_;
  r.Rs_Ohm = (v_high_V_ - v_low_V_) / delta_i_A;
  // Moments about the high level: e = v - V2 - Rs (i - I2) is sigma Ls di/dt + Lm/Lr dpsi_r/dt.
  const T m0_v = sv_.value() - v_high_V_ * k0_.value();
  const T m0_i = si_.value() - i_high_meas_A_ * k0_.value();
  const T m1_v = stv_.value() - v_high_V_ * k1v_.value();
  const T m1_i = sti_.value() - i_high_meas_A_ * k1i_.value();
  r.Ls_H = (m0_v - r.Rs_Ohm * m0_i) / delta_i_A;
  r.sigma_Ls_H = period_s_ * sdd_.value() / sdi_.value();
  r.Lm2_over_Lr_H = r.Ls_H - r.sigma_Ls_H;
  const T m1 = m1_v - r.Rs_Ohm * m1_i;
  r.tau_r_s = (m1 + r.Ls_H * m0_i) / (delta_i_A * r.Lm2_over_Lr_H);
  result_ = r;
  const bool plausible = r.Rs_Ohm > T(0) && r.sigma_Ls_H > T(0) && r.Lm2_over_Lr_H > T(0) &&
                         r.tau_r_s > T(0) && std::isfinite(r.Rs_Ohm) && std::isfinite(r.Ls_H) &&
                         std::isfinite(r.sigma_Ls_H) && std::isfinite(r.tau_r_s);
  if (plausible) {
    enter(IdentificationStep::done);
  } else {
    fail(IdentificationFailure::implausible);
  }
}

template <typename T>
T StandstillIdentifier<T>::fraction() const noexcept {
  switch (step_) {
    case IdentificationStep::low_level:
    case IdentificationStep::high_level: {
      if (holding_) {
        return T(0.5) + T(0.5) * T(hold_.ticks) / T(std::max<uint32_t>(1, hold_.hold_ticks));
      }
      return T(0.5) * settle_.progress();
    }
    case IdentificationStep::transient_inductance:
      return std::min(T(1), T(ticks_) / T(hf_ticks_));
    case IdentificationStep::ramp_down:
      return std::min(T(1), T(ticks_) / T(ramp_ticks_));
    case IdentificationStep::done:
    case IdentificationStep::failed:
      return T(1);
  }
  return T(0);
}

template class StandstillIdentifier<float>;
template class StandstillIdentifier<double>;

}  // namespace imd::firmware
