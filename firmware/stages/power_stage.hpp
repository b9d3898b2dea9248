#pragma once
/// The modulate stage's interface: what turns the law's command into what acts on the motor.
/// On a board that is the inner feedback (2) run digitally, the voltage limit and SVPWM on the
/// PWM (SvpwmStage); a simulation may substitute the paper's analog inner-loop circuit or an
/// ideal current source (hal_sim/drive/) through the same interface. modulate() computes, and
/// write() applies once protection has passed; the PWM's enable gates every power stage.
/// Tick context.
#include <cmath>

#include "control/frames.hpp"
#include "control/svpwm.hpp"
#include "control/voltage_fed_model.hpp"
#include "firmware/laws/control_law.hpp"
#include "hal/pwm.hpp"

namespace imd::firmware {

template <typename T>
struct Modulation {
  /// The rotor-frame input v~ that will really act (after the voltage limit), for the
  /// observers and the prediction.
  control::Vec2<T> v_acting_AB_V = control::Vec2<T>::Zero();
  control::Vec2<T> u_alphabeta_V = control::Vec2<T>::Zero();  ///< stator voltage command
  /// The stator voltage that will act (the command after the voltage limit); zero from a
  /// power stage that does not know it (an ideal current source).
  control::Vec2<T> u_acting_alphabeta_V = control::Vec2<T>::Zero();
  hal::PhaseDuties duty{0.5f, 0.5f, 0.5f};
  bool clipped = false;  ///< the request exceeded the linear range and was scaled down
  /// The duties were computed outside the power stage (the commissioning, DC braking) and are
  /// written as they are.
  bool direct = false;
  bool finite = true;    ///< false: a NaN or Inf on the way to the power stage
};

/// A voltage written as it is (the commissioning, DC braking): SVPWM only, no inner feedback.
template <typename T>
inline Modulation<T> direct_modulation(const control::Vec2<T>& u_alphabeta_V, T v_bus_V) noexcept {
  Modulation<T> out;
  out.u_alphabeta_V = u_alphabeta_V;
  const control::SvpwmResult<T> pwm = control::svpwm(u_alphabeta_V, v_bus_V);
  for (int phase = 0; phase < 3; ++phase) out.duty[phase] = static_cast<float>(pwm.duty[phase]);
  out.clipped = pwm.clipped;
  out.finite = control::all_finite(u_alphabeta_V.x(), u_alphabeta_V.y());
  out.direct = true;
  return out;
}

template <typename T>
class PowerStage {
 protected:
  // Never deleted through the interface (nothing is allocated): no virtual destructor, so
  // no deleting destructor and no operator delete in the vtables of the firmware.
  ~PowerStage() = default;

 public:
  /// What the law's output becomes over the period that starts in state `x_input`.
  virtual Modulation<T> modulate(const LawOutput<T>& law,
                                 const control::RotorFrameState<T>& x_input,
                                 T v_bus_V) noexcept = 0;
  /// Applies it and enables the stage.
  virtual void write(const Modulation<T>& m) noexcept = 0;
};

}  // namespace imd::firmware
