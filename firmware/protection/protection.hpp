#pragma once
/// The protect stage: every trip decision of the tick, in one place, right after the PWM write
/// (which the PWM latches for the next period). It returns the faults found (Trip); the
/// supervisor latches them and the PWM goes off in the same tick, before those duties act. The
/// checks, in the order in which the first fault is named (docs/safety.md):
///   1. the board's enable input lost while the inverter drives the motor;
///   2. while calibrating: an ADC offset beyond its limit;
///   3. in every state: over-current (or an ADC code on a rail), bus over-voltage, over-speed,
///      a non-finite estimate, the encoder;
///   4. while the inverter drives the motor (and nothing above tripped): bus under-voltage, a
///      stuck ADC, a lost phase, the command watchdog;
///   5. then (nothing above tripped): the magnetizing timeout (from the rotor time constant), a
///      law without solution, a non-finite output.
/// The tick's execution time is judged at its end (over_budget). Tick context except
/// construction.
#include <algorithm>
#include <cmath>
#include <cstdint>

#include "control/motor_parameters.hpp"
#include "control/real.hpp"
#include "control/voltage_fed_model.hpp"
#include "firmware/drive_config.hpp"
#include "firmware/laws/control_law.hpp"
#include "firmware/protection/adc_stuck_check.hpp"
#include "firmware/protection/encoder_check.hpp"
#include "firmware/protection/law_failure_check.hpp"
#include "firmware/protection/phase_loss_check.hpp"
#include "firmware/protection/trip.hpp"
#include "firmware/stages/estimate.hpp"
#include "firmware/stages/measurement.hpp"
#include "firmware/stages/power_stage.hpp"

namespace imd::firmware {

/// What the supervisor knows that the checks need (TickPlan carries it).
struct SupervisedState {
  bool modulating = false;   ///< magnetizing, running or stopping: the inverter drives
  bool enable_input = true;  ///< the board's enable input (true without one)
  bool restarted = false;    ///< enabled or cleared this tick: the checks start afresh
  bool magnetizing = false;
  /// A fault's DC braking: the estimates have no position to rest on (the encoder failed), so
  /// the checks that use them (encoder, phase loss) do not judge.
  bool dc_braking = false;
  /// The holding brake may still hold the rotor (engaged, or released less than its release
  /// time ago): the load is unbounded, so the encoder check judges only jumps.
  bool brake_may_hold = false;
  bool watchdog_armed = false;         ///< CAN-commanded and magnetizing or running
  uint32_t magnetizing_ticks = 0;      ///< since magnetizing began (saturates; 0 if not)
  uint32_t command_silence_ticks = 0;  ///< since the last valid command (saturates; 0 unarmed)
};

/// The checks built from the motor parameters: they are part of the motor model, rebuilt with
/// it (firmware/motor_model.hpp). Without them (no motor record) the drive cannot modulate, and
/// the encoder check, which needs the motor's motion model, is skipped.
template <typename T>
struct MotorChecks {
  /// `c`: the motor's exact model at the sample period; `counts_per_rev`, `adc_A_per_code`:
  /// the board's encoder and ADC.
  MotorChecks(const control::MotorParameters& motor, const control::VoltageFedCoefficients& c,
              const DriveConfig& config, Real counts_per_rev, Real adc_A_per_code) noexcept;
  void reset() noexcept {
    encoder.reset();
    idle();
  }
  /// The inverter does not drive the motor (or a fault turned it off): the checks that judge
  /// the driven motor start afresh.
  void idle() noexcept {
    adc_stuck.reset();
    phase_loss.idle();
    law_failure.reset();
  }
  /// Takes over the checks' state from the model this one replaces (firmware/motor_model.hpp).
  void continue_from(const MotorChecks& old) noexcept {
    encoder.continue_from(old.encoder);
    adc_stuck.continue_from(old.adc_stuck);
    phase_loss.continue_from(old.phase_loss);
    law_failure.continue_from(old.law_failure);
  }

  /// The encoder check's load bound: max_load_share of the torque at the current limit with
  /// this rotor flux (the flux current |psi|/Lm first, the rest torque current), within the
  /// torque limit. From the squared flux: |psi| sqrt(i_q^2) is one square root,
  /// sqrt(|psi|^2 i_q^2). Tick context.
  T max_load_Nm(T flux2_Wb2) const noexcept {
    const T i_q2 = current_limit_A * current_limit_A - flux2_Wb2 * (per_Lm_H * per_Lm_H);
    const T torque = i_q2 > T(0) && flux2_Wb2 > T(0)
                         ? torque_per_AWb * std::sqrt(flux2_Wb2 * i_q2)
                         : T(0);
    return max_load_share * std::min(torque, torque_limit_Nm);
  }

  T pole_pairs, torque_per_AWb;
  T max_load_share, torque_limit_Nm, current_limit_A, per_Lm_H;
  /// Magnetizing longer than this is a fault (firmware/protection/magnetizing_timeout.hpp).
  uint32_t magnetizing_timeout_ticks;
  EncoderCheck<T> encoder;
  AdcStuckCheck<T> adc_stuck;
  PhaseLossCheck<T> phase_loss;
  LawFailureCheck law_failure;
};

template <typename T>
class Protection {
 public:
  explicit Protection(const DriveConfig& config) noexcept;

  /// `motor`: the motor model's checks, null without a motor record.
  Trip check(const Measurement<T>& m, const Estimate<T>& e, const SupervisedState& s,
             const LawOutput<T>& law, const Modulation<T>& out, MotorChecks<T>* motor) noexcept;
  /// The tick took `exec_counts` of the execution clock: an overrun past the budget.
  Trip over_budget(uint32_t exec_counts) const noexcept;
  /// The budget in execution-clock counts (0: not checked), for a clock of `clock_Hz`.
  void set_clock(uint32_t clock_Hz) noexcept;

 private:
  [[gnu::always_inline]] void check_sensed(const Measurement<T>& m, const Estimate<T>& e,
                                           bool modulating, MotorChecks<T>* motor,
                                           Trip& trip) noexcept;
  [[gnu::always_inline]] void check_driving(const Measurement<T>& m, const Estimate<T>& e,
                                            const SupervisedState& s, MotorChecks<T>& motor,
                                            Trip& trip) noexcept;

  ProtectionConfig config_;
  bool commands_over_can_;
  T overcurrent_A_, bus_min_V_, bus_max_V_, overspeed_rad_s_;
  uint32_t command_timeout_ticks_;
  uint32_t budget_counts_ = 0;
};

}  // namespace imd::firmware
