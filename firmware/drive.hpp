#pragma once
/// The drive's control tick, run by the control timer at 10 kHz:
///   sense (ADC, encoder) -> estimate (observers, rotation into the rotor frame) -> control
///   (magnetizing current or DSMC, one-step prediction over the PWM latency) -> inner feedback
///   (2) executed digitally -> limits -> SVPWM -> protection -> PWM write -> record.
/// States (firmware/state_machine.hpp): ADC offset calibration with the PWM off, idle until
/// enabled, magnetizing (B_k is singular at zero flux), running, stopping on a disable command.
/// Every protection check runs before the PWM write; a fault turns the PWM off in the same tick
/// and latches until a clear_faults command. Commands arrive on CAN (bounded per tick) and
/// telemetry leaves through the CAN transmit queue (docs/can/protocol.md, docs/safety.md).
/// T is the control arithmetic: float on the MCU, double on the host.
#include <cstdint>

#include "control/deadbeat_current.hpp"
#include "control/dsmc.hpp"
#include "control/encoder_observer.hpp"
#include "control/voltage_fed_model.hpp"
#include "control/flux_observer.hpp"
#include "control/load_estimator.hpp"
#include "control/motor_parameters.hpp"
#include "firmware/commanded_reference.hpp"
#include "firmware/drive_config.hpp"
#include "firmware/drive_state.hpp"
#include "firmware/execution_stats.hpp"
#include "firmware/iol_stage.hpp"
#include "firmware/protection/adc_stuck_check.hpp"
#include "firmware/protection/encoder_check.hpp"
#include "firmware/protection/phase_loss_check.hpp"
#include "firmware/protocol/commands.hpp"
#include "firmware/reference_source.hpp"
#include "firmware/speed_ramp.hpp"
#include "firmware/state_machine.hpp"
#include "firmware/state_oracle.hpp"
#include "firmware/telemetry.hpp"
#include "firmware/tick_record.hpp"
#include "hal/analog_inner_loop.hpp"
#include "hal/can_bus.hpp"
#include "hal/control_timer.hpp"
#include "hal/current_adc.hpp"
#include "hal/current_source.hpp"
#include "hal/encoder.hpp"
#include "hal/gpio.hpp"
#include "hal/pwm.hpp"

namespace imd::firmware {

struct DrivePeripherals {
  hal::Pwm& pwm;
  hal::Encoder& encoder;
  hal::CurrentAdc& adc;
  hal::ControlTimer& timer;
  hal::AnalogInnerLoop* analog_inner_loop = nullptr;  ///< only with config.analog_inner_loop
  hal::CurrentSource* current_source = nullptr;       ///< only with config.current_source
  hal::CanBus* can = nullptr;  ///< commands and telemetry; without it the drive is local only
  hal::Gpio* gpio = nullptr;   ///< the lines DriveConfig names (enable, fault, timing)
};

template <typename T>
class Drive final : public hal::TickHandler {
 public:
  /// Wires the drive; no allocation after this. `references` is used unless the config takes
  /// them from CAN commands. `oracle` (simulation only) gives ideal sensors.
  Drive(const control::MotorParameters& motor, const DriveConfig& config,
        const DrivePeripherals& peripherals, const ReferenceSource<T>& references,
        const StateOracle<T>* oracle = nullptr);

  void on_tick() noexcept override;
  /// For a program that stops the drive (Linux: Ctrl-C, SIGTERM), after the last tick: turns the
  /// PWM off, goes to idle if modulating (reason shutdown; the motor coasts), and sends a final
  /// heartbeat. `k` is the tick count at the stop.
  void shut_down(uint64_t k) noexcept;

  DriveState state() const noexcept { return machine_.state(); }
  /// The first latched fault (none when not faulted).
  FaultCode fault() const noexcept { return status_.first_fault; }
  const DriveStatus& status() const noexcept { return status_; }
  const StateMachine& state_machine() const noexcept { return machine_; }
  const protocol::CommandDecoder& commands() const noexcept { return decoder_; }
  const Telemetry& telemetry() const noexcept { return telemetry_; }
  const TickRecord<T>& record() const noexcept { return record_; }
  const ExecutionStats& execution() const noexcept { return execution_; }

 private:
  using Vec2 = control::Vec2<T>;

  struct Estimate {
    control::RotorFrameState<T> x;  ///< at this tick
    T load_Nm = T(0);
  };

  bool calibrate_adc(const hal::AdcSample& sample) noexcept;
  Estimate estimate(const hal::AdcSample& sample) noexcept;
  /// The checks on what was sensed and estimated this tick (docs/safety.md).
  void protect(uint64_t k, const Estimate& e, const hal::AdcSample& sample, T v_bus_V) noexcept;
  /// Magnetizing, running or stopping: the control law, limits and the PWM write. Returns the
  /// rotor-frame v~ that will act (zero if a check tripped).
  Vec2 control(uint64_t k, const Estimate& e, T v_bus_V) noexcept;
  // Commands (drive_commands.cpp).
  void receive_commands(uint64_t k) noexcept;
  protocol::CommandResult apply(const protocol::Command& command, uint64_t k) noexcept;
  void enable(uint64_t k) noexcept;
  void clear_faults(uint64_t k) noexcept;
  control::InputDisk<T> feasible_inputs(const control::RotorFrameState<T>& x,
                                        T v_bus_V) const noexcept;
  /// The magnetizing current: along the flux (the A axis while there is none), of the size that
  /// holds the reference flux in steady state (rotor flux for the DSMC, stator flux for the IOL).
  Vec2 magnetizing_current(const control::RotorFrameState<T>& x,
                           const Reference<T>& ref) const noexcept;
  /// The squared flux the start-up waits for, and its reference.
  T magnetized_flux2(const control::RotorFrameState<T>& x) const noexcept;
  T magnetized_flux2_ref(const Reference<T>& ref) const noexcept;
  Vec2 compensation_AB(const control::RotorFrameState<T>& x) const noexcept;
  /// Turns the PWM off and latches the fault (the first one keeps its code and time).
  void trip(FaultCode code, uint64_t k, uint8_t detail = 0) noexcept;
  void pwm_off() noexcept;
  /// Drives one of the board's output lines (nothing when the line is not wired).
  void write_line(int line, bool level) noexcept;
  /// The hardware enable input; true when the board has none.
  bool enable_input_active() const noexcept;
  bool modulating() const noexcept;
  T electromagnetic_torque_Nm(const control::RotorFrameState<T>& x) const noexcept;

  /// The configuration values the tick uses, in the tick's arithmetic (converted once).
  struct Limits {
    T adc_offset_limit_A, modulation_margin, current_limit_A, magnetizing_current_A;
    T magnetizing_current_max_A, magnetized_fraction, half_period_s, stop_speed_rad_s;
    T overcurrent_A, bus_min_V, bus_max_V, overspeed_rad_s;
    T command_accel_step_rad_s, stop_accel_step_rad_s;  ///< per period, for the speed ramp
    bool current_limited;  ///< i_max_A is finite
  };
  static Limits limits(const DriveConfig& config) noexcept;

  DriveConfig config_;
  Limits limits_;
  DrivePeripherals hw_;
  CommandedReference<T> commanded_;
  const ReferenceSource<T>& references_;  ///< commanded_ or the profile given at construction
  const StateOracle<T>* oracle_;

  control::VoltageFedCoefficients coefficients_;
  control::VoltageFedModel<T> model_;
  control::Dsmc<T> dsmc_;
  control::FluxObserver<T> flux_observer_;
  control::EncoderObserver<T> encoder_observer_;
  control::LoadEstimator<T> load_estimator_;
  control::DeadbeatCurrent<T> current_loop_;
  SpeedRamp<T> speed_ramp_;
  IolStage<T> iol_stage_;
  T sigma_H_, beta_per_H_, pole_pairs_, Lm_H_, Ls_H_, Lm_over_Lr_, a21_, a22_, b2_;
  T torque_per_AWb_;  ///< k_T p Lm / Lr

  StateMachine machine_;
  DriveStatus status_;
  ControllerKind controller_;
  protocol::CommandDecoder decoder_;
  Telemetry telemetry_;
  EncoderCheck<T> encoder_check_;
  AdcStuckCheck<T> adc_stuck_check_;
  PhaseLossCheck<T> phase_loss_check_;
  uint64_t magnetizing_start_tick_ = 0, magnetizing_timeout_ticks_ = 0;
  uint64_t last_command_tick_ = 0, command_timeout_ticks_ = 0;
  uint64_t stop_start_tick_ = 0, stop_timeout_ticks_ = 0;
  int32_t encoder_delta_counts_ = 0;  ///< counts over the last period
  Vec2 u_written_V_ = Vec2::Zero();   ///< last stator voltage command (alpha-beta)
  bool calibrated_ = false;  ///< the ADC offsets are known
  bool enable_input_ = true;  ///< the hardware enable input, read at the start of the tick
  bool fault_line_level_ = false;
  int calibration_count_ = 0;
  int64_t calibration_sum_[3] = {0, 0, 0};
  T offset_code_[3] = {T(0), T(0), T(0)};
  uint32_t last_encoder_count_ = 0;
  int32_t encoder_position_ = 0;       ///< counts within one revolution, [0, cpr)
  bool encoder_started_ = false;       ///< the first reading has set the observer's angle
  Vec2 v_in_flight_V_ = Vec2::Zero();  ///< written last tick, acts over this period (latency 1)
  T peak_phase_current_A_ = T(0);      ///< largest phase current of this tick
  T phase_current_A_[3] = {T(0), T(0), T(0)};
  bool adc_saturated_ = false;  ///< a phase-current code on a rail this tick
  TickRecord<T> record_;
  ExecutionStats execution_;
};

}  // namespace imd::firmware
