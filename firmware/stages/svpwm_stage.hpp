#pragma once
/// The board's power stage: the inner feedback (2) executed digitally, sampled and held. The
/// held voltage is rotated to the middle of the period it acts on, where the analog law's
/// rotation is on average; SVPWM turns it into duties; beyond the linear range the vector is
/// scaled down, and the input v~ that really acts is computed back from it, so that the
/// observers see what is applied. The duties then get the dead time's loss added back
/// (dead_time_compensation.hpp). Tick context except construction.
#include <cmath>

#include "control/real.hpp"
#include "control/svpwm.hpp"
#include "firmware/stages/dead_time_compensation.hpp"
#include "firmware/stages/input_limits.hpp"
#include "firmware/stages/power_stage.hpp"
#include "hal/pwm.hpp"

namespace imd::firmware {

template <typename T>
class SvpwmStage final : public PowerStage<T> {
 public:
  SvpwmStage(hal::Pwm& pwm, const control::MotorParameters& motor, Real period_s,
             const DeadTimeCompensation<T>& dead_time) noexcept
      : pwm_(pwm), feedback_(motor), dead_time_(dead_time), half_period_s_(T(period_s / 2)) {}

  Modulation<T> modulate(const LawOutput<T>& law, const control::RotorFrameState<T>& x,
                         T v_bus_V) noexcept override {
    Modulation<T> m;
    m.v_acting_AB_V = law.v_AB_V;
    const control::Vec2<T> compensation = feedback_.compensation_AB_V(x);
    const auto rotation = control::Rotation<T>::from_angle(
        feedback_.pole_pairs() * (x.theta_mech_rad + x.omega_mech_rad_s * half_period_s_));
    m.u_alphabeta_V = rotation.apply(compensation + law.v_AB_V);
    const control::SvpwmResult<T> pwm = control::svpwm(m.u_alphabeta_V, v_bus_V);
    m.clipped = pwm.clipped;
    m.u_acting_alphabeta_V = m.u_alphabeta_V;
    if (pwm.clipped) {
      const T limit = control::svpwm_linear_limit_V(v_bus_V);
      const T magnitude = m.u_alphabeta_V.norm();
      m.u_acting_alphabeta_V *= magnitude > limit ? limit / magnitude : T(1);
      m.v_acting_AB_V = rotation.apply_inverse(m.u_acting_alphabeta_V) - compensation;
    }
    m.finite = control::all_finite(m.u_alphabeta_V.x(), m.u_alphabeta_V.y(), m.v_acting_AB_V.x(),
                                   m.v_acting_AB_V.y());
    m.duty = {float(pwm.duty[0]), float(pwm.duty[1]), float(pwm.duty[2])};
    if (dead_time_.active()) dead_time_.apply(m.duty, rotation.apply(x.i_s_AB_A), v_bus_V);
    return m;
  }

  void write(const Modulation<T>& m) noexcept override {
    pwm_.set_duties(m.duty);
    pwm_.enable();
  }

 private:
  hal::Pwm& pwm_;
  InnerFeedback<T> feedback_;
  DeadTimeCompensation<T> dead_time_;
  T half_period_s_;
};

}  // namespace imd::firmware
