#include "firmware/identification/inertia_identifier.hpp"

#include <algorithm>
#include <cmath>

namespace imd::firmware {

template <typename T>
InertiaIdentifier<T>::InertiaIdentifier(const InertiaSettings<T>& plan,
                                        const StandstillResult<T>& motor) noexcept
    : period_s_(plan.period_s),
      rad_per_count_(plan.rad_per_count),
      pole_pairs_(plan.pole_pairs),
      v_limit_V_(plan.v_limit_V),
      Lm2_over_Lr_H_(motor.Lm2_over_Lr_H),
      tau_r_s_(motor.tau_r_s),
      sigma_Ls_H_(motor.sigma_Ls_H),
      kp_Ohm_(motor.sigma_Ls_H * plan.crossover_rad_s),
      ki_T_Ohm_(motor.Rs_Ohm * plan.crossover_rad_s * plan.period_s),
      flux_decay_(std::exp(-plan.period_s / motor.tau_r_s)),
      max_accelerate_ticks_(plan.max_accelerate_ticks),
      max_coast_ticks_(plan.max_coast_ticks),
      ramp_ticks_(plan.ramp_ticks),
      brake_extra_ticks_(plan.brake_extra_ticks) {
  // Rules (docs/identification.md, "Inertia and friction"):
  // * the field at the motor's no-load magnetizing current, V_phase / (omega_rated Ls), at
  //   most 0.7 of the test's current limit;
  // * the test speed at 0.3 of rated, and at most where the back EMF takes half the voltage;
  // * the torque current so that the inertia guessed from the nameplate reaches the test
  //   speed in accelerate_s, between 0.1 and 0.5 of the current the field leaves.
  const T i_limit_A = plan.i_limit_A;
  i_d_A_ =
      std::min(plan.v_phase_peak_V / (plan.omega_rated_rad_s * motor.Ls_H), T(0.7) * i_limit_A);
  const T omega_e_test =
      std::min(T(0.3) * plan.omega_rated_rad_s, T(0.5) * v_limit_V_ / (motor.Ls_H * i_d_A_));
  omega_test_rad_s_ = omega_e_test / pole_pairs_;
  k_torque_Nm_per_A_ = T(1.5) * pole_pairs_ * Lm2_over_Lr_H_ * i_d_A_;
  const T i_free_A = std::sqrt(std::max(T(0), i_limit_A * i_limit_A - i_d_A_ * i_d_A_));
  const T i_q_wanted_A =
      plan.J_guess_kgm2 * omega_test_rad_s_ / (plan.accelerate_s * k_torque_Nm_per_A_);
  i_q_A_ = std::clamp(i_q_wanted_A, T(0.1) * i_free_A, T(0.5) * i_free_A);
  const T flux_s = std::max(T(5) * motor.tau_r_s, T(0.05));
  flux_ticks_ = static_cast<uint32_t>(flux_s / period_s_);
}

template <typename T>
void InertiaIdentifier<T>::stop(InertiaOutcome why) noexcept {
  outcome_ = why;
  if (why != InertiaOutcome::measured && why != InertiaOutcome::no_motion) {
    enter(InertiaStep::failed);  // the PWM goes off; the motor coasts
  } else {
    omega_brake_from_rad_s_ = omega_block_rad_s_;
    enter(InertiaStep::brake);
  }
}

template <typename T>
void InertiaIdentifier<T>::take_row(int row) noexcept {
  row_theta_[row] = T(counts_) * rad_per_count_;
  row_int_theta_[row] = int_theta_.value();
  row_int2_torque_[row] = int2_torque_.value();
}

template <typename T>
void InertiaIdentifier<T>::solve() noexcept {
  // J theta_i + B Theta_i = Y_i, i = end of acceleration, end of coast.
  const T a = row_theta_[0] * row_int_theta_[1], b = row_theta_[1] * row_int_theta_[0];
  const T det = a - b;
  // A coast that barely moved on makes the two rows one: nothing to solve (a normal run's
  // determinant is about half its larger term).
  if (!(std::abs(det) > T(0.05) * std::max(std::abs(a), std::abs(b)))) {
    stop(InertiaOutcome::implausible);
    return;
  }
  const T J =
      (row_int2_torque_[0] * row_int_theta_[1] - row_int2_torque_[1] * row_int_theta_[0]) / det;
  const T B = (row_theta_[0] * row_int2_torque_[1] - row_theta_[1] * row_int2_torque_[0]) / det;
  result_ = {J, B};
  stop(J > T(0) && std::isfinite(J) && std::isfinite(B) ? InertiaOutcome::measured
                                                        : InertiaOutcome::implausible);
}

template <typename T>
control::Vec2<T> InertiaIdentifier<T>::step(const Vec2& i_A,
                                            int32_t encoder_delta_counts) noexcept {
  ++ticks_;
  ++ticks_in_[int(step_)];
  if (finished()) return Vec2::Zero();
  // The field frame moves by the rotor's electrical angle and the slip over the last period.
  theta_e_rad_ += pole_pairs_ * T(encoder_delta_counts) * rad_per_count_ + slip_rad_s_ * period_s_;
  theta_e_rad_ = std::remainder(theta_e_rad_, T(2 * 3.14159265358979));
  const auto frame = control::Rotation<T>::from_angle(theta_e_rad_);
  const Vec2 i_dq_A = frame.apply_inverse(i_A);
  // The current model of the rotor flux, as lambda = Lm/Lr psi_r: the torque is 1.5 p lambda iq.
  lambda_Wb_ =
      Lm2_over_Lr_H_ * i_dq_A.x() + flux_decay_ * (lambda_Wb_ - Lm2_over_Lr_H_ * i_dq_A.x());
  const T torque_Nm = T(1.5) * pole_pairs_ * lambda_Wb_ * i_dq_A.y();
  slip_rad_s_ = lambda_Wb_ > T(0.05) * Lm2_over_Lr_H_ * i_d_A_
                    ? Lm2_over_Lr_H_ * i_dq_A.y() / (tau_r_s_ * lambda_Wb_)
                    : T(0);
  // The speed over blocks of 10 ms of counts (a count is too coarse for one period).
  block_counts_ += encoder_delta_counts;
  if (T(++block_ticks_) * period_s_ >= T(0.01)) {
    omega_block_rad_s_ = T(block_counts_) * rad_per_count_ / (T(block_ticks_) * period_s_);
    block_counts_ = 0;
    block_ticks_ = 0;
  }
  omega_e_rad_s_ = pole_pairs_ * omega_block_rad_s_ + slip_rad_s_;

  // The drive's own overspeed check needs the observers, which do not run here: this step
  // guards its speed itself. A rotor that turns against the torque's direction means an
  // encoder counting against the phase sequence, and a field that cannot be oriented.
  if (std::abs(omega_block_rad_s_) > T(2) * omega_test_rad_s_) {
    stop(InertiaOutcome::overspeed);
    return Vec2::Zero();
  }
  // From rest under a positive torque the angle only grows; 5 degrees the other way is no
  // quantization.
  if (step_ == InertiaStep::accelerate && T(counts_) * rad_per_count_ < T(-0.087)) {
    stop(InertiaOutcome::wrong_direction);
    return Vec2::Zero();
  }

  T i_q_ref_A = T(0);
  switch (step_) {
    case InertiaStep::flux_up:
      i_d_ref_A_ = i_d_A_;
      if (ticks_ >= flux_ticks_) {
        // The equations start from rest.
        if (std::abs(omega_block_rad_s_) > T(0.02) * omega_test_rad_s_) {
          stop(InertiaOutcome::not_at_rest);
          return Vec2::Zero();
        }
        enter(InertiaStep::accelerate);
      }
      break;
    case InertiaStep::accelerate:
    case InertiaStep::coast: {
      counts_ += encoder_delta_counts;
      int_theta_.add(T(counts_) * rad_per_count_ * period_s_);
      int_torque_.add(torque_Nm * period_s_);
      int2_torque_.add(int_torque_.value() * period_s_);
      if (step_ == InertiaStep::accelerate) {
        i_q_ref_A = i_q_A_;
        const bool at_speed = omega_block_rad_s_ >= omega_test_rad_s_;
        if (ticks_ == max_accelerate_ticks_ / 2) half_time_counts_ = counts_;
        if (at_speed) {
          take_row(0);
          accelerate_ticks_ = ticks_;
          omega_coast_from_rad_s_ = omega_block_rad_s_;
          enter(InertiaStep::coast);
        } else if (ticks_ >= max_accelerate_ticks_) {
          // Out of time: a locked shaft (under a radian turned), a speed that stopped growing
          // (a load or friction above the test torque, or a field not oriented: wrong pole
          // pairs or encoder resolution), or a heavy rotor still accelerating: measured if it
          // got far enough, else too heavy for the test.
          accelerate_ticks_ = ticks_;  // what the brake may take
          const bool moved = T(counts_) * rad_per_count_ > T(1);
          // Judged on the angle, which the encoder resolves in thousands of counts, not on the
          // block speed, which a creeping rotor gives as one or two counts. From rest, the
          // angle of the whole time over that of its first half is 4 at a constant
          // acceleration and 2 at a settled speed: above 3, the rotor still accelerates.
          const bool still_accelerating = counts_ > 3 * half_time_counts_;
          if (!moved) {
            stop(InertiaOutcome::no_motion);
          } else if (!still_accelerating) {
            stop(InertiaOutcome::stalled);
          } else if (omega_block_rad_s_ >= T(0.2) * omega_test_rad_s_) {
            take_row(0);
            omega_coast_from_rad_s_ = omega_block_rad_s_;
            enter(InertiaStep::coast);
          } else {
            stop(InertiaOutcome::no_motion);
          }
        }
      } else {
        // As long as the acceleration took (at least 0.1 s); shorter if friction halves the
        // speed first.
        const auto min_ticks = static_cast<uint32_t>(T(0.1) / period_s_);
        const uint32_t coast_ticks =
            std::min(std::max(accelerate_ticks_, min_ticks), max_coast_ticks_);
        const bool slowed =
            ticks_ >= min_ticks && omega_block_rad_s_ < T(0.5) * omega_coast_from_rad_s_;
        if (ticks_ >= coast_ticks || slowed) {
          take_row(1);
          solve();
        }
      }
      break;
    }
    case InertiaStep::brake:
      i_q_ref_A = omega_block_rad_s_ > T(0) ? -i_q_A_ : T(0);
      if (omega_block_rad_s_ <= T(0.02) * omega_test_rad_s_) {
        enter(InertiaStep::ramp_down);
      } else if (ticks_ > accelerate_ticks_ + brake_extra_ticks_) {
        stop(InertiaOutcome::not_at_rest);  // something drives the shaft: PWM off
        return Vec2::Zero();
      }
      break;
    case InertiaStep::ramp_down:
      i_d_ref_A_ = i_d_A_ * (T(1) - std::min(T(1), T(ticks_) / T(ramp_ticks_)));
      if (ticks_ >= ramp_ticks_) {
        enter(InertiaStep::done);
        return Vec2::Zero();
      }
      break;
    case InertiaStep::done:
    case InertiaStep::failed:
      return Vec2::Zero();
  }

  // PI per axis with the decoupling feedforward, the integral clamped with the output.
  const Vec2 error(i_d_ref_A_ - i_dq_A.x(), i_q_ref_A - i_dq_A.y());
  const Vec2 feedforward_V(-omega_e_rad_s_ * sigma_Ls_H_ * i_q_ref_A,
                           omega_e_rad_s_ * (sigma_Ls_H_ * i_d_ref_A_ + lambda_Wb_));
  integral_V_ += ki_T_Ohm_ * error;
  Vec2 u_dq = kp_Ohm_ * error + integral_V_ + feedforward_V;
  const T magnitude = u_dq.norm();
  if (magnitude > v_limit_V_) {
    u_dq *= v_limit_V_ / magnitude;
    integral_V_ = u_dq - kp_Ohm_ * error - feedforward_V;
    if (++saturated_ticks_ > 100) stop(InertiaOutcome::voltage_limit);
  } else {
    saturated_ticks_ = 0;
  }
  if (step_ == InertiaStep::failed) return Vec2::Zero();
  // Written now, the voltage acts over the period after next: turned on by 1.5 periods.
  return control::Rotation<T>::from_angle(theta_e_rad_ + T(1.5) * omega_e_rad_s_ * period_s_)
      .apply(u_dq);
}

template <typename T>
T InertiaIdentifier<T>::fraction() const noexcept {
  const auto share = [](T x) { return std::clamp(x, T(0), T(1)); };
  switch (step_) {
    case InertiaStep::flux_up:
      return share(T(ticks_) / T(flux_ticks_));
    case InertiaStep::accelerate:
      return share(omega_block_rad_s_ / omega_test_rad_s_);
    case InertiaStep::coast:
      return share(T(ticks_) / T(std::max<uint32_t>(1, accelerate_ticks_)));
    case InertiaStep::brake:
      return omega_brake_from_rad_s_ > T(0)
                 ? share(T(1) - omega_block_rad_s_ / omega_brake_from_rad_s_)
                 : T(1);
    case InertiaStep::ramp_down:
      return share(T(ticks_) / T(ramp_ticks_));
    case InertiaStep::done:
    case InertiaStep::failed:
      return T(1);
  }
  return T(0);
}

template class InertiaIdentifier<float>;
template class InertiaIdentifier<double>;

}  // namespace imd::firmware
