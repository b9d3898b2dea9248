#pragma once
/// The law stage's interface: a control law computes, once per tick while the drive runs, the
/// rotor-frame input for the period after the one in flight. Each law is a small adapter
/// (firmware/laws/) around its mathematics in control/; the laws are listed in one place,
/// firmware/laws/law_registry.hpp. The magnetizing start-up is the supervisor's, not the
/// law's: a law starts from a magnetized motor. Tick context except construction.
#include <cstdint>

#include "control/frames.hpp"
#include "control/input_disk.hpp"
#include "firmware/limitation.hpp"
#include "firmware/reference_source.hpp"
#include "firmware/stages/estimate.hpp"

namespace imd::firmware {

/// The flux a law regulates, which the magnetizing start-up therefore raises.
enum class ControlledFlux : uint8_t { rotor, stator };

template <typename T>
struct LawInput {
  const Estimate<T>& e;       ///< the state at this tick and at the input's period (x_input)
  const Reference<T>& now;    ///< references at x_input's step, the speed through the ramp
  const Reference<T>& next;   ///< at the step after: what the input should reach
  const Reference<T>& ahead;  ///< lookahead_ticks() ahead (the speed still next's)
  bool stopping;
  const control::InputDisk<T>& feasible;  ///< the inputs the voltage and current limits allow
  T v_max_V;  ///< the stator voltage the modulation reaches (+inf without a voltage limit)
};

template <typename T>
struct LawOutput {
  control::Vec2<T> v_AB_V = control::Vec2<T>::Zero();      ///< rotor-frame input v~
  control::Vec2<T> i_cmd_AB_A = control::Vec2<T>::Zero();  ///< current command (current laws)
  bool ok = true;  ///< false: the law had no solution (B_k singular): a fault
};

/// What the laws report beyond their output, kept in the tick record for telemetry and plots.
/// A law writes its own fields; the record holds them from tick to tick.
template <typename T>
struct LawDiagnostics {
  /// This tick: the limit that cut what the law's speed or flux channel wanted, the feasible
  /// input set first (Limitation::input), then the current, then the torque limit.
  Limitation limit = Limitation::none;
  // The sliding-mode law.
  T discriminant = T(0), c_k = T(0), det_B = T(0);
  bool speed_saturated = false, flux_saturated = false;  ///< this tick
  // The current-fed law, at its last T0 boundary.
  T torque_ref_Nm = T(0), torque_cmd_Nm = T(0), y2 = T(0), y2_ref = T(0);
  T stator_flux2_est_Wb2 = T(0);
  control::Vec2<T> i_held_AB_A = control::Vec2<T>::Zero();  ///< current assumed held now
  bool torque_limited = false;
  bool iol_boundary = false;  ///< the law ran this tick
  // The field-oriented law.
  T flux_ref_Wb = T(0);        ///< rotor-flux reference after field weakening
  T slip_rad_s = T(0);         ///< electrical slip of its rotor-flux model
  bool voltage_limited = false;  ///< this tick: its voltage was cut to the disk
};

template <typename T>
class ControlLaw {
 protected:
  // Never deleted through the interface (nothing is allocated): no virtual destructor, so
  // no deleting destructor and no operator delete in the vtables of the firmware.
  ~ControlLaw() = default;

 public:
  virtual ControlledFlux controlled_flux() const noexcept = 0;
  /// Whether the law follows a speed reference (or only a torque reference).
  virtual bool follows_speed() const noexcept = 0;
  /// How far ahead the law looks into the references (LawInput::ahead), in ticks.
  virtual uint32_t lookahead_ticks() const noexcept { return 0; }
  /// The drive starts running in state x (estimated, magnetized) with this rotor-frame current
  /// commanded (the magnetizing current).
  virtual void start(const control::RotorFrameState<T>& x,
                     const control::Vec2<T>& i_AB_A) noexcept {
    (void)x;
    (void)i_AB_A;
  }
  virtual LawOutput<T> step(const LawInput<T>& in, LawDiagnostics<T>& report) noexcept = 0;
  /// After the PWM write, on the state x_input this tick's step acted on and its voltage disk:
  /// what the next step needs but this one's output does not wait for (a limit that moves with
  /// the speed), off the latency from sense to write.
  virtual void after_write(const control::RotorFrameState<T>& x_input, T v_max_V) noexcept {
    (void)x_input;
    (void)v_max_V;
  }
};

}  // namespace imd::firmware
