#pragma once
/// Configuration of the drive application. In-class defaults are safe for the paper-000 motor;
/// scenario and board files override them (validated on load).
#include <cstdint>
#include <limits>

#include "control/real.hpp"
#include "firmware/protection/protection_config.hpp"

namespace imd::firmware {

/// The control laws, by their number on CAN (firmware/laws/law_registry.hpp lists them).
enum class ControllerKind : uint8_t {
  dsmc,  ///< paper 000: sliding modes on speed and rotor flux
  iol,   ///< paper 001: input-output linearization of torque and stator flux
  ifoc,  ///< indirect field-oriented control: the classic drive's baseline
};
inline constexpr int kControllerCount = 3;

struct DriveConfig {
  Real sample_period_s = Real(1e-4);  ///< control period delta
  ControllerKind controller = ControllerKind::dsmc;
  /// Ticks between a duty write and its effect; the tick predicts that far with the exact
  /// model (0 or 1).
  int pwm_latency_ticks = 1;
  /// Predict over the latency with the exact model (the default). Off only to measure what the
  /// prediction is worth.
  bool compensate_latency = true;

  // The current-fed controller (iol).
  Real iol_period_s = Real(1e-3);  ///< T0, a whole number of sample periods
  /// Ticks from a current command to the current: 1 for the deadbeat current loop on the PWM
  /// (it reaches its target one tick after it acts); 0 for a power stage that imposes the
  /// current at once (the simulation's ideal current source).
  int current_response_ticks = 1;
  bool outer_speed_loop = false;  ///< v1 from a speed PI (else the torque reference)
  bool outer_flux_loop = false;   ///< v2 from the Fig. 5 loop (else from (21))
  Real speed_loop_bandwidth_rad_s = 30.0;
  Real torque_limit_Nm = 240.0;
  Real flux_loop_time_constant_s = Real(0.01);

  // The field-oriented controller (ifoc); 0: the rules of docs/ifoc.md.
  Real ifoc_current_bandwidth_rad_s = 0.0;
  Real ifoc_speed_bandwidth_rad_s = 0.0;

  // Control law.
  Real max_accel_rad_s2 = std::numeric_limits<Real>::infinity();  ///< speed reference ramp
  Real speed_reaching_pole = 0.0;  ///< e_{k+1} = pole e_k; 0 is the paper's deadbeat law
  Real flux_reaching_pole = 0.0;
  /// The DSMC's speed channel: through the torque of the next step (false, the default; its
  /// speed error decays at dsmc_speed_bandwidth_rad_s), or the paper's, which sets the next
  /// step's speed directly with speed_reaching_pole (true: to reproduce paper 000).
  bool dsmc_paper_speed_channel = false;
  Real dsmc_speed_bandwidth_rad_s = 0.0;  ///< 0: the IFOC's rule (docs/control.md)

  // Limits.
  bool voltage_limited = true;      ///< false only to reproduce the paper (no limit)
  Real modulation_margin = Real(0.95);  ///< share of the SVPWM linear range the law may use
  Real i_max_A = std::numeric_limits<Real>::infinity();  ///< motor and inverter current limit
  Real current_margin = Real(0.95);                      ///< share of i_max the law may plan for

  // The inverter.
  Real dead_time_s = 0.0;            ///< the PWM dead time per switching edge the board programs
  bool compensate_dead_time = true;  ///< add the dead time's voltage loss back to the duties

  // Start-up.
  int adc_calibration_ticks = 256;     ///< offset measurement with the PWM off; 0 skips it
  Real adc_offset_limit_A = 0.5;       ///< a larger measured offset is a fault
  Real magnetizing_current_A = 0.0;    ///< 0: sqrt(flux2_ref)/Lm, capped at 0.9 i_max
  Real magnetized_fraction = Real(0.95);  ///< running once |Phi^|^2 >= this * reference
  /// The magnetizing timeout's floor: the timeout is twice the model's magnetizing time, at least
  /// this (firmware/protection/magnetizing_timeout.hpp).
  Real magnetizing_timeout_s = 2.0;

  // Estimation.
  Real encoder_observer_bandwidth_rad_s = 400.0;
  /// Use the paper's Section IV estimators (flux observer and load estimator on a measured
  /// speed) instead of the encoder observer's speed and load.
  bool section_iv_load_estimator = false;
  Real load_estimator_pole = Real(0.99);  ///< double pole of the error matrix (13)
  Real min_flux2_Wb2 = Real(1e-3);        ///< below it B_k counts as singular

  // Rotor-resistance tracking (docs/robustness.md): a reactive-power MRAS estimates Rr while
  // a law runs, and the model is rebuilt on the estimate outside the tick.
  bool rotor_resistance_tracking = true;
  Real rr_convergence_time_constant_s = 0.0;  ///< at slip tangent 1; 0: 4 tau_r
  /// Rebuild once the estimate is this far from the model (0: at every interval, even on the
  /// same value: what the tests use to exercise the swap).
  Real rr_retune_share = Real(0.005);
  Real rr_retune_interval_s = Real(0.05);  ///< and no more often than this

  ProtectionConfig protection;
  /// The tick's stages are timed on one tick in this many (1: every tick); the whole tick is
  /// timed on every tick for its budget.
  int stage_timing_period_ticks = 8;

  // Commands and telemetry (docs/can/protocol.md).
  uint8_t node_id = 1;
  /// References from CAN commands (set_speed, set_flux) with the command watchdog; otherwise
  /// from the ReferenceSource given at construction (a scenario profile).
  bool commands_over_can = false;
  /// Enable once calibrated, without a command (scenario profiles).
  bool auto_enable = false;
  int telemetry_rate_Hz = 100;  ///< fast telemetry, 10..1000
  Real min_flux2_command_Wb2 = Real(0.01);  ///< smallest set_flux accepted (10 x min_flux2_Wb2)
  Real max_flux2_Wb2 = 4.0;                 ///< largest set_flux accepted
  /// Initial references over CAN, before any set_speed or set_flux.
  Real flux2_ref_Wb2 = Real(0.2), stator_flux2_ref_Wb2 = 1.0;

  // Board lines: indices into DrivePeripherals::gpio, -1 where the board has none.
  /// Hardware enable input (safe-torque-off style interlock): while it is inactive the drive
  /// refuses enable, and losing it while the PWM is on trips fault enable_input.
  int enable_input_line = -1;
  int fault_output_line = -1;   ///< active while a fault is latched
  /// Active (driven) to release the holding brake: only while the drive runs or ramps to a
  /// controlled stop; a spring-applied brake engages when the line drops or loses power.
  int brake_output_line = -1;
  /// The brake's release time (its datasheet's): after the line releases it, the brake may
  /// still hold the rotor this long.
  Real brake_release_time_s = Real(0.1);
  int timing_output_line = -1;  ///< active while the tick computes (to watch on a scope)

  // Disable: ramp to a stop, then PWM off.
  Real stop_decel_rad_s2 = 200.0;
  Real stop_speed_rad_s = 1.0;  ///< PWM off once the ramp is at 0 and |speed| below this
  Real stop_timeout_s = 10.0;   ///< PWM off after this even if the motor still turns
};

}  // namespace imd::firmware
