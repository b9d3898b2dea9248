#pragma once
/// The supervise stage: the drive's state machine (firmware/state_machine.hpp) and its command
/// handling. Every state transition happens here: commands from CAN, the end of the ADC
/// calibration, the magnetizing start-up handing over to the law, the end of a stop, and the
/// faults the protect stage found (latch). It also shapes the references the law sees: the
/// speed through the acceleration ramp, at the steps the law's input acts on. Its output, the
/// TickPlan, tells the law stage what to run. Tick context except construction.
#include <cstdint>

#include "control/frames.hpp"
#include "firmware/commanded_reference.hpp"
#include "firmware/drive_config.hpp"
#include "firmware/drive_state.hpp"
#include "firmware/laws/law_registry.hpp"
#include "firmware/parameters/parameter_bank.hpp"
#include "firmware/protection/protection.hpp"
#include "firmware/protection/stop_category.hpp"
#include "firmware/protection/trip.hpp"
#include "firmware/protocol/commands.hpp"
#include "firmware/reference_source.hpp"
#include "firmware/speed_ramp.hpp"
#include "firmware/stages/estimate.hpp"
#include "firmware/stages/magnetizer.hpp"
#include "firmware/stages/measurement.hpp"
#include "firmware/state_machine.hpp"
#include "firmware/telemetry.hpp"
#include "hal/can_bus.hpp"
#include "hal/gpio.hpp"

namespace imd::firmware {

/// What the law stage runs this tick.
enum class Mode : uint8_t {
  off,          ///< the PWM is off (calibrating, idle, fault)
  magnetizing,  ///< the magnetizing current
  controlling,  ///< the selected law (running or stopping)
  identifying,  ///< the commissioning drives the motor
  dc_braking,   ///< a fault's DC-injection stop (firmware/stages/dc_brake.hpp)
};

/// What a fault's stop needs to know of the motion when it latches.
template <typename T>
struct StopContext {
  T omega_mech_rad_s = T(0);  ///< the speed estimate at detection
  uint64_t dc_brake_ticks = 0;  ///< how long DC braking takes from there; 0: not possible
};

template <typename T>
struct TickPlan {
  Mode mode;
  bool stopping;
  /// References at the input's step and the step after (the speed through the ramp), and the
  /// law's lookahead; while off, `next` is the reference of this tick (for telemetry).
  Reference<T> now, next, ahead;
  bool restarted = false;  ///< enabled or cleared this tick: the checks start afresh
};

/// Where the supervisor's commands and events go.
struct SupervisorWiring {
  hal::CanBus* can = nullptr;
  hal::Gpio* gpio = nullptr;
  Telemetry& telemetry;
  ParameterBank* parameters = nullptr;  ///< the motor record CAN reads and writes; none: refused
};

template <typename T>
class Supervisor {
 public:
  /// `references`: the reference source unless the config takes references from CAN commands.
  /// `laws`, `magnetizer`: the motor model's (null: no motor record yet).
  /// `calibrated`: the ADC offsets are known without a calibration.
  Supervisor(const DriveConfig& config, const SupervisorWiring& wiring,
             const ReferenceSource<T>* references, LawRegistry<T>* laws,
             const Magnetizer<T>* magnetizer, bool predicts_latency, bool calibrated) noexcept;

  /// A new motor model is in use (unconfigured -> idle), or none (null: the drive is
  /// unconfigured until one arrives).
  void attach(LawRegistry<T>* laws, const Magnetizer<T>* magnetizer, uint64_t k) noexcept;

  /// Commands, then the transitions the measurement and the estimate call for, then the
  /// references. Running on, the plan prepare(k - 1) made; the reference is valid until the
  /// next plan() or prepare().
  const TickPlan<T>& plan(uint64_t k, const Measurement<T>& m, const Estimate<T>& e) noexcept;
  /// What the checks need of tick k's plan p, after the PWM write (off the latency from sense
  /// to write; nothing between the plan and the checks changes the state).
  SupervisedState supervised(uint64_t k, const TickPlan<T>& p) const noexcept;
  /// After tick k's PWM write and trip decisions: the plan tick k + 1 takes if the drive runs
  /// on, made off the path to the next write. plan(k + 1) takes it unless what it depends on
  /// changed meanwhile (a command, a fault, a transition, the ramp), and then makes its own:
  /// the same plan either way.
  void prepare(uint64_t k) noexcept;
  /// Latches the faults the protect stage found (the first one keeps its code and time) and
  /// starts their stop (firmware/protection/stop_category.hpp). True: STO, the caller turns the
  /// PWM off now; false: a controlled stop (SS1 or DC braking) runs, or continues, first.
  /// Cold, as every fault path and command handler here: built for size (a fault or a command
  /// is a rare tick).
  [[gnu::cold]] bool latch(const Trip& trip, uint64_t k,
                           const StopContext<T>& motion = {}) noexcept;
  /// A fault's controlled stop is under way (the state is stopping, the fault latched).
  bool fault_stopping() const noexcept { return fault_stop_; }
  /// The program running the drive ends: to idle if modulating (the motor coasts).
  void shut_down(uint64_t k) noexcept;
  /// The commissioning run ended at tick k: with a result (`done`), or with `failure`.
  void identification_ended(uint64_t k, bool done, uint8_t failure) noexcept;
  /// Its progress, for the telemetry.
  void identification_progress(uint8_t step, float fraction) noexcept {
    status_.identify_step = step;
    status_.identify_fraction = fraction;
  }

  DriveState state() const noexcept { return machine_.state(); }
  /// The PWM runs (magnetizing, running, stopping or identifying). Inline: the tick asks
  /// several times.
  bool modulating() const noexcept {
    const DriveState s = machine_.state();
    return s == DriveState::magnetizing || s == DriveState::running ||
           s == DriveState::stopping || s == DriveState::identifying;
  }
  /// The holding brake may be released: the drive runs, or ramps to a controlled stop.
  bool brake_released() const noexcept {
    return machine_.state() == DriveState::running ||
           (machine_.state() == DriveState::stopping && status_.stop != StopCategory::dc_brake);
  }
  const DriveStatus& status() const noexcept { return status_; }
  DriveStatus& status() noexcept { return status_; }
  const StateMachine& machine() const noexcept { return machine_; }
  const protocol::CommandDecoder& decoder() const noexcept { return decoder_; }
  /// The selected law; only while a motor model is attached (configured).
  ControlLaw<T>& law() noexcept { return laws_->law(controller_); }
  const ControlLaw<T>& law() const noexcept { return laws_->law(controller_); }
  /// The selected law's flux (kept at selection: the tick asks for it several times).
  ControlledFlux controlled_flux() const noexcept { return controlled_flux_; }

 private:
  [[gnu::always_inline]] void references(uint64_t k, const Estimate<T>& e, TickPlan<T>& p) noexcept;
  /// Tick k's references through the ramp as it stands; `ramp_k1_rad_s` is where the ramp goes.
  /// Out of line: plan and prepare share one copy (a read ahead taken calls it not at all).
  [[gnu::noinline]] void shaped(uint64_t k, bool stopping, Reference<T>& now, Reference<T>& next,
                                T& ramp_k1_rad_s) const noexcept;
  // Commands (supervisor_commands.cpp).
  /// The parameter bank's answer and the CAN commands (with a CAN bus only).
  void receive_commands(uint64_t k, bool& restarted) noexcept;
  /// The plan made afresh (plan() without a prepared one to take). Not inlined: the running
  /// tick's path through plan() stays a short function.
  [[gnu::noinline]] const TickPlan<T>& replan(uint64_t k, const Measurement<T>& m,
                                              const Estimate<T>& e, bool restarted) noexcept;
  [[gnu::cold]] protocol::CommandResult apply(const protocol::Command& command, uint64_t k,
                                              bool& restarted) noexcept;
  [[gnu::cold]] void enable(uint64_t k, bool& restarted) noexcept;
  [[gnu::cold]] protocol::CommandResult clear_faults(uint64_t k, bool& restarted) noexcept;
  /// A fault's controlled stop ended (at standstill, or at its time limit): STO.
  [[gnu::cold]] void end_fault_stop(uint64_t k, TickPlan<T>& p) noexcept;
  bool read_enable_input() const noexcept;
  void select(ControllerKind kind) noexcept;
  /// The state the drive rests in once calibrated: idle, or unconfigured without a model.
  DriveState rest_state() const noexcept {
    return laws_ != nullptr ? DriveState::idle : DriveState::unconfigured;
  }
  [[gnu::cold]] protocol::CommandResult access_parameter(const protocol::Command& c, uint64_t k,
                                                         bool& restarted) noexcept;
  /// The answers the service loop has ready; a write that completed a record starts the
  /// change of model (idle -> unconfigured).
  [[gnu::cold]] void answer_served_access(uint64_t k) noexcept;
  [[gnu::cold]] void answer_parameter(const ParameterAnswer& a) noexcept;
  bool commands_over_can_, auto_enable_;
  int enable_input_line_;
  SupervisorWiring wiring_;
  CommandedReference<T> commanded_;
  const ReferenceSource<T>& references_;  ///< commanded_ or the given source
  LawRegistry<T>* laws_;
  const Magnetizer<T>* magnetizer_;
  bool predicts_latency_;
  ControllerKind controller_;
  ControlledFlux controlled_flux_;  ///< of the selected law
  uint32_t lookahead_ticks_;        ///< of the selected law
  StateMachine machine_;
  DriveStatus status_;
  protocol::CommandDecoder decoder_;
  SpeedRamp<T> ramp_;
  T command_accel_step_rad_s_, stop_accel_step_rad_s_;  ///< per period
  T stop_speed_rad_s_;
  uint64_t stop_timeout_ticks_;
  StopPolicy stop_policy_;
  bool fault_stop_ = false;          ///< a fault's SS1 or DC braking runs
  uint64_t dc_brake_end_tick_ = 0;
  bool calibrated_;
  bool record_complete_, record_saved_;  ///< as the last parameter answer said
  T v_bus_V_ = T(0);                     ///< measured this tick (the commissioning's plan)
  bool enable_input_ = true;  ///< read at the start of the stage
  /// Bumped by whatever changes the references or the ramp's limit (a command applied, an
  /// enable, a fault latched), and by a model attached, which drops a read-ahead to be safe.
  uint32_t generation_ = 0;
  /// The plan prepare() made for tick `k` (kNotPrepared: none).
  struct Prepared {
    static constexpr uint64_t kNotPrepared = UINT64_MAX;
    uint64_t k = kNotPrepared;
    uint32_t generation = 0;
    T ramp_k1_rad_s = T(0);  ///< the ramp's value it leaves
    TickPlan<T> plan{};
  } prepared_;
  TickPlan<T> plan_{};  ///< the plan plan() made itself
  uint64_t magnetizing_start_tick_ = 0, last_command_tick_ = 0, stop_start_tick_ = 0;
};

}  // namespace imd::firmware
