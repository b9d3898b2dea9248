#pragma once
/// The drive: one control tick per period of the control timer, as a sequence of stages that
/// hand values to each other (docs/architecture.md has the picture):
///   sense -> estimate -> supervise -> law -> modulate -> actuate -> protect -> publish
/// sense: ADC and encoder -> Measurement; estimate: observers and the prediction over the PWM
/// latency -> Estimate; supervise: commands and state transitions -> TickPlan; law: the
/// magnetizing current or the selected control law -> LawOutput; modulate: inner feedback (2),
/// limits, SVPWM -> Modulation; actuate: the PWM write (latched for the next period); protect:
/// every trip decision -> Trip, latched, and the PWM off before the written duties act; publish:
/// the tick record and CAN telemetry. What the PWM write does not wait for runs after it: the
/// trip decisions, the observers advanced over the next period, the rotor-resistance
/// tracker's step and the next tick's references (Supervisor::prepare).
/// Each stage is timed. T is the control arithmetic: float on the MCU, double on the host.
#include <atomic>
#include <cstdint>
#include <optional>
#include <type_traits>
#include <variant>

#include "control/motor_parameters.hpp"
#include "control/voltage_fed_model.hpp"
#include "firmware/drive_config.hpp"
#include "firmware/drive_state.hpp"
#include "firmware/execution_stats.hpp"
#include "firmware/image_features.hpp"
#include "firmware/identification/commissioning.hpp"
#include "firmware/laws/law_registry.hpp"
#include "firmware/limitation.hpp"
#include "firmware/motor_model.hpp"
#include "firmware/parameters/parameter_bank.hpp"
#include "firmware/protection/protection.hpp"
#include "firmware/reference_source.hpp"
#include "firmware/stages/estimate.hpp"
#include "firmware/stages/input_limits.hpp"
#include "firmware/stages/latency_predictor.hpp"
#include "firmware/stages/magnetizer.hpp"
#include "firmware/stages/sense.hpp"
#include "firmware/stages/svpwm_stage.hpp"
#include "firmware/supervisor.hpp"
#include "firmware/telemetry.hpp"
#include "firmware/tick_record.hpp"
#include "hal/can_bus.hpp"
#include "hal/control_timer.hpp"
#include "hal/current_adc.hpp"
#include "hal/encoder.hpp"
#include "hal/gpio.hpp"
#include "hal/parameter_store.hpp"
#include "hal/pwm.hpp"
#include "hal/watchdog.hpp"

namespace imd::firmware {

/// The board's peripherals the drive is wired to.
struct DrivePeripherals {
  hal::Pwm& pwm;
  hal::Encoder& encoder;
  hal::CurrentAdc& adc;
  hal::ControlTimer& timer;
  hal::CanBus* can = nullptr;  ///< commands and telemetry; without it the drive is local only
  hal::Gpio* gpio = nullptr;   ///< the lines DriveConfig names (enable, fault, timing)
  hal::ParameterStore* store = nullptr;  ///< where a save puts the motor record; none: refused
  hal::Watchdog* watchdog = nullptr;     ///< fed at the end of every tick; none: not fed
  hal::ResetCause reset_cause = hal::ResetCause::power_on;  ///< the board's, for the heartbeat
};

/// Parts that replace the drive's own, each optional (null: the board's part). A reference
/// profile replaces the CAN commands' references when the config does not take them from CAN;
/// a simulation substitutes its ideal sensors and the papers' power stages (hal_sim/drive/).
template <typename T>
struct DriveSubstitutes {
  const ReferenceSource<T>* references = nullptr;
  Sensing<T>* sensing = nullptr;
  StateEstimator<T>* estimator = nullptr;
  PowerStage<T>* power_stage = nullptr;
};

template <typename T>
class Drive final : public hal::TickHandler {
 public:
  /// Wires the drive; no allocation after this. `record`: the motor record loaded from storage
  /// (firmware/parameters/motor_record.hpp), valid; without one the drive waits, unconfigured,
  /// for a record written over CAN.
  Drive(const std::optional<MotorRecord>& record, const DriveConfig& config,
        const DrivePeripherals& peripherals, const DriveSubstitutes<T>& substitutes = {});
  Drive(const Drive&) = delete;
  Drive& operator=(const Drive&) = delete;

  void on_tick() noexcept override;
  /// What must not run in the tick: rebuilding the motor model after a parameter write, and
  /// saving the record. The program calls it from its main loop, never from the tick; it
  /// returns at once when nothing is pending. The tick does not touch the model meanwhile.
  void service() noexcept;
  /// For a program that stops the drive (Linux: Ctrl-C, SIGTERM), after the last tick: turns the
  /// PWM off, goes to idle if modulating (reason shutdown; the motor coasts), and sends a final
  /// heartbeat. `k` is the tick count at the stop.
  void shut_down(uint64_t k) noexcept;

  DriveState state() const noexcept { return supervisor_.state(); }
  /// The first latched fault (none when not faulted).
  FaultCode fault() const noexcept { return supervisor_.status().first_fault; }
  const DriveStatus& status() const noexcept { return supervisor_.status(); }
  const StateMachine& state_machine() const noexcept { return supervisor_.machine(); }
  const protocol::CommandDecoder& commands() const noexcept { return supervisor_.decoder(); }
  const Telemetry& telemetry() const noexcept { return telemetry_; }
  const TickRecord<T>& record() const noexcept { return record_; }
  const ExecutionStats& execution() const noexcept { return execution_; }
  /// The rate of the execution clock that TickRecord::stage_counts are counted in.
  uint32_t execution_clock_Hz() const noexcept { return clock_Hz_; }
  /// The motor record the drive runs on, if it has a complete one (not for tick context).
  std::optional<control::MotorParameters> motor() const noexcept;
  /// How often the service loop rebuilt the model on a tracked rotor resistance.
  uint32_t retunes() const noexcept { return retunes_; }
  /// Whether the rotor resistance is tracked: configured, and the board's own power stage (a
  /// substituted one, the paper's analog circuit or an ideal current source, does not report
  /// the voltage it applies, which the tracker needs).
  bool tracking_rotor_resistance() const noexcept { return tracking_; }
  const ParameterBank& parameters() const noexcept { return bank_; }

 private:
  using Vec2 = control::Vec2<T>;

  // The stages are named functions for reading, and inlined into on_tick (each call of its
  // own costs ~1 % of the tick on the MCU).
  /// The model the tick may use (null: none, or being rebuilt), attached on its arrival.
  [[gnu::always_inline]] MotorModel<T>* model(uint64_t k) noexcept;
  /// A parameter write asked for a new model: the tick lets go of the old one.
  void release_model() noexcept;
  /// Service loop: the model rebuilt on the tracked rotor resistance, when it moved enough.
  void retune() noexcept;
  /// Service loop: a new record replaces the model (and any retuned one in waiting).
  void rebuild(const control::MotorParameters& motor) noexcept;
  [[gnu::always_inline]] Estimate<T> estimate(const Measurement<T>& m,
                                              MotorModel<T>* model) noexcept;
  /// estimate() of a valid measurement with a model: one named result, built in its caller's
  /// place (a function that also returns another object would copy it there).
  [[gnu::always_inline]] Estimate<T> observe(const Measurement<T>& m,
                                             MotorModel<T>& model) noexcept;
  [[gnu::always_inline]] LawOutput<T> law(const TickPlan<T>& plan, const Estimate<T>& e,
                                          T v_bus_V, MotorModel<T>* model) noexcept;
  [[gnu::always_inline]] Modulation<T> modulate(const TickPlan<T>& plan, const LawOutput<T>& u,
                                                const Estimate<T>& e, const Measurement<T>& m,
                                                MotorModel<T>* model) noexcept;
  /// The commissioning's tick: its voltage from the measured current, straight to SVPWM.
  Modulation<T> identify(const Measurement<T>& m) noexcept;
  /// A fault's DC braking: its stator voltage from the measured current, straight to SVPWM.
  Modulation<T> dc_brake(const Measurement<T>& m, const Estimate<T>& e,
                         MotorModel<T>& model) noexcept;
  /// After the tick: a finished commissioning hands its result to the service loop. The tick
  /// calls it only while one runs or hands over (adopt_pending_): most ticks, neither.
  void end_identification(uint64_t k) noexcept;
  // The service loop's side of the commissioning.
  void plan_commissioning() noexcept;
  void adopt_commissioning() noexcept;
  /// The PWM write of what the tick modulated, or the PWM off when nothing is. Returns whether
  /// the written voltage is the law's (or DC braking's), which the observers must learn.
  [[gnu::always_inline]] bool actuate(const Modulation<T>& out, MotorModel<T>* model) noexcept;
  /// After the write: the faults found (and an overrun) latched, the PWM off for an STO before
  /// the written duties act, and what acts over the next period kept for the observers.
  [[gnu::always_inline]] void react(uint64_t k, const Estimate<T>& e, const Modulation<T>& out,
                                    const Trip& trip, const Trip& overrun, bool law_voltage,
                                    MotorModel<T>* model) noexcept;
  /// After the PWM write, what the write does not wait for: the observers advanced over the
  /// next period, the law's work for the next tick, and the rotor-resistance tracker's step
  /// (it feeds only the service loop). `law_stepped`: this tick's law() stepped the law.
  [[gnu::always_inline]] void after_write(const Measurement<T>& m, const Estimate<T>& e,
                                          bool law_stepped, const Vec2& u_acted_V,
                                          MotorModel<T>* model) noexcept;
  /// The execution time up to the PWM write, against its budget: the overrun trip, if any.
  [[gnu::always_inline]] Trip check_budget(uint32_t counts) noexcept;
  [[gnu::always_inline]] void publish(uint64_t k, const Measurement<T>& m, const Estimate<T>& e,
                                      const TickPlan<T>& plan, const LawOutput<T>& u,
                                      const Modulation<T>& out, MotorModel<T>* model) noexcept;
  void pwm_off() noexcept;
  /// Drives one of the board's output lines (nothing when the line is not wired).
  void write_line(int line, bool level) noexcept;

  DriveConfig config_;
  DrivePeripherals hw_;
  DriveSubstitutes<T> substitutes_;
  BoardScales board_;
  BoardSensing<T> board_sensing_;
  Sensing<T>& sensing_;
  ParameterBank bank_;
  /// Built outside the tick (construction, service); the tick uses models_[active_] through
  /// attached_. The other slot takes a model on a tracked rotor resistance, which the tick
  /// swaps in (retune_ready_) and which then takes over the state.
  std::optional<MotorModel<T>> models_[2];
  uint8_t active_ = 0;  ///< changed by the tick only on a swap, before it clears retune_ready_
  std::atomic<bool> model_ready_;  ///< the active model is whole: set by service, cleared by tick
  std::atomic<bool> retune_ready_{false};  ///< the other slot is whole: set by service
  MotorModel<T>* attached_;        ///< tick side: the model in use, null while none
  std::atomic<float> rr_estimate_Ohm_{0.0f};  ///< the tick's latest estimate, for the service
  std::atomic<uint32_t> tick_published_{0};  ///< the tick count, for the service loop's pace
  uint32_t last_retune_tick_ = 0;
  uint32_t retunes_ = 0;
  bool tracking_;  ///< the tracker may move Rr (config, and a power stage that knows its voltage)
  /// Planned by the service loop on an identify command, then run by the tick; nothing in an
  /// image without the commissioning (firmware/image_features.hpp).
  std::conditional_t<kCommissioningInImage, std::optional<Commissioning<T>>, std::monostate>
      identifier_;
  bool adopt_pending_ = false;  ///< its result still waits for the bank (tick side)
  Protection<T> protection_;
  Telemetry telemetry_;
  Supervisor<T> supervisor_;

  uint32_t clock_Hz_;
  float ns_per_count_;               ///< execution-clock counts to ns
  T rad_s_per_count_;  ///< an encoder count per period, as a mean speed over the period
  Vec2 v_applied_V_ = Vec2::Zero();  ///< rotor-frame input written this tick (zero if off)
  Vec2 u_last_period_V_ = Vec2::Zero();  ///< stator voltage that acted over [k-1, k]
  // Set after the trip decisions for after_write (tick side).
  Vec2 v_acting_V_ = Vec2::Zero();  ///< rotor-frame input acting over [k, k+1]
  bool observers_due_ = false;      ///< the observers advance with it
  bool tracker_due_ = false;        ///< the rotor-resistance tracker steps
  bool tracker_adapts_ = false;     ///< and may move its estimate
  bool fault_line_level_ = false;
  bool brake_line_level_ = false;  ///< released (driven) or engaged
  uint64_t brake_released_tick_ = 0;  ///< when the line last released the brake
  int ticks_since_timed_ = 0;  ///< for the stage timing of one tick in N
  TickRecord<T> record_;
  ExecutionStats execution_;
  LimitedMonitor limited_;  ///< whether a limit holds the running drive back
  uint64_t brake_release_ticks_;  ///< the brake's release time
};

}  // namespace imd::firmware
