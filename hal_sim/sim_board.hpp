#pragma once
/// The simulated board: the motor plant behind every HAL interface, advanced in lock-step with
/// the control timer. One call of run_tick() is one control period:
///   1. the ADC and encoder latch the plant state at t_k;
///   2. the timer runs the firmware's tick handler;
///   3. the plant integrates [t_k, t_{k+1}] with what the inverter (or the analog inner-loop
///      device) applies: with one tick of latency, the duties written at tick k act from k+1.
/// With the PWM disabled the inverter is off and the stator currents are zero (the free-
/// wheeling transient, a fraction of a millisecond, is not modelled). With `current_source` the
/// stator current is imposed by the ideal current source instead (paper 001's current-fed
/// plant); the PWM enable still gates it.
///
/// Faults (hal_sim/fault_injection.hpp) are injected with inject(), between ticks.
///
/// No heap, no exceptions: the board also builds for the MCU of a processor-in-the-loop run.
#include <cstddef>
#include <cstdint>
#include <limits>

#include "control/motor_parameters.hpp"
#include "hal_sim/fault_injection.hpp"
#include "hal_sim/induction_motor_plant.hpp"
#include "hal_sim/inverter_model.hpp"
#include "hal_sim/load_profile.hpp"
#include "hal_sim/sensor_models.hpp"
#include "hal_sim/sim_peripherals.hpp"

namespace imd::sim {

enum class InnerFeedback {
  digital,       ///< the firmware runs (2) sampled and held; the PWM drives the motor
  ideal_analog,  ///< (2) is evaluated continuously by the analog device (paper's scheme)
};

/// The windings heating (or cooling) over a run: the plant's resistances go linearly from their
/// value at t = 0 to `scale_end` times it at `duration_s`, and stay there.
struct ResistanceDrift {
  double Rs_scale_end = 1.0;
  double Rr_scale_end = 1.0;
  double duration_s = 0.0;  ///< 0: no drift
  bool active() const noexcept {
    return duration_s > 0.0 && (Rs_scale_end != 1.0 || Rr_scale_end != 1.0);
  }
};

/// A spring-applied holding brake on the shaft, released while the drive drives its line
/// (firmware DriveConfig::brake_output_line). Its armature follows the line after a delay.
struct HoldingBrake {
  static constexpr int kLine = 3;  ///< the board's GPIO line that releases it
  double holding_torque_Nm = 0.0;  ///< 0: no brake fitted
  double engage_delay_s = 0.03;    ///< line dropped -> torque on
  double release_delay_s = 0.05;   ///< line driven -> torque off
};

struct SimBoardConfig {
  double period_s = 1e-4;
  int substeps = 10;          ///< RK4 steps per period
  /// How the plant integrates a period (plant_integrator.hpp); RK4 with `substeps` by default.
  PlantIntegrator integrator = PlantIntegrator::rk4;
  int pwm_latency_ticks = 1;  ///< 0 or 1
  InnerFeedback inner_feedback = InnerFeedback::digital;
  bool current_source = false;  ///< the ideal current source drives the motor
  double v_bus_V = 311.0;       ///< nominal DC bus (a bus fault changes the board's v_bus_V())
  InverterNonideality inverter;  ///< dead time and device drop (PWM-driven motor only)
  /// The inverter's switches over each period (switching_inverter.hpp) instead of its average:
  /// the current ripple within the period is simulated (slower).
  bool switching_inverter = false;
  uint32_t encoder_cpr = 8192;
  AdcModelConfig adc;
  uint64_t seed = 1;
  ResistanceDrift drift;
  HoldingBrake brake;
};

class SimBoard {
 public:
  /// Requires valid parameters and config (the scenario loader validates them).
  SimBoard(const control::MotorParameters& motor, const SimBoardConfig& config);

  hal::Pwm& pwm() noexcept { return pwm_; }
  hal::Encoder& encoder() noexcept { return encoder_; }
  hal::CurrentAdc& adc() noexcept { return adc_; }
  hal::CanBus& can() noexcept { return can_; }
  hal::Gpio& gpio() noexcept { return gpio_; }
  hal::ControlTimer& timer() noexcept { return timer_; }
  SimAnalogInnerLoop& analog_inner_loop() noexcept { return analog_; }
  SimCurrentSource& current_source() noexcept { return current_source_; }
  SimCan& can_side() noexcept { return can_; }
  const SimPwm& pwm_side() const noexcept { return pwm_; }
  SimPwm& pwm_side() noexcept { return pwm_; }

  InductionMotorPlant& plant() noexcept { return plant_; }
  const InductionMotorPlant& plant() const noexcept { return plant_; }
  const SimBoardConfig& config() const noexcept { return config_; }

  void set_load_profile(const LoadProfile& profile) noexcept {
    load_ = profile;
    load_time_s_ = std::numeric_limits<double>::quiet_NaN();  // evaluate it anew
  }
  /// Load torque over the current period (held, hypothesis H1). Kept for the plant's time: a
  /// lock-step period asks for it before the tick and end_period() again (the same value).
  double load_Nm() const noexcept {
    const double t_s = plant_.time_s();
    if (!(t_s == load_time_s_)) {
      load_time_s_ = t_s;
      load_at_time_Nm_ = load_.at(t_s);
    }
    return load_at_time_Nm_;
  }
  /// Stator voltage the plant saw over the last period (alpha-beta); for the analog device, the
  /// value at the start of the period.
  /// With an open phase this is the inverter's output; the plant's terminal voltage differs
  /// from it along the open phase's axis.
  const Vec2& applied_voltage_V() const noexcept { return applied_voltage_V_; }
  /// Torque and stator flux at the start of the last period, with the current of that period
  /// (after the step a current source makes at the period's start).
  double start_torque_Nm() const noexcept { return start_torque_Nm_; }
  const Vec2& start_flux_s_alphabeta_Wb() const noexcept { return start_flux_s_alphabeta_Wb_; }
  const Vec2& start_current_alphabeta_A() const noexcept { return start_current_alphabeta_A_; }

  void run_tick();
  /// run_tick() in two halves, for a firmware paced by another timer (the Linux real-time
  /// loop): begin_period() latches the sensors at t_k, the caller runs the firmware's tick,
  /// end_period() integrates [t_k, t_{k+1}]. The board's own timer() is not used then.
  void begin_period();
  void end_period();
  /// Between the two halves: the board's own timer runs the firmware's tick.
  void fire_timer() noexcept { timer_.fire(); }

  /// Applies a fault at once (FaultKind documents each); it lasts to the end of the run. Call
  /// between ticks: the next run_tick() sees it. Returns false and changes nothing when a
  /// parameter is out of its range (fault_parameter_error says which).
  [[nodiscard]] bool inject(const FaultInjection& fault) noexcept;
  /// Repairs a fault inject() applied (FaultInjection::until_s says how). Call between ticks.
  void repair(const FaultInjection& fault) noexcept;
  /// How many faults inject() has applied.
  std::size_t injected_count() const noexcept { return injected_count_; }
  /// The DC bus now: config().v_bus_V until a bus fault changes it.
  double v_bus_V() const noexcept { return v_bus_V_; }
  bool encoder_frozen() const noexcept { return encoder_frozen_; }
  bool adc_stuck() const noexcept { return adc_stuck_; }
  /// The holding brake's torque acts on the shaft (after its delays).
  bool brake_engaged() const noexcept { return brake_engaged_; }

 private:
  void latch_sensors();
  /// The plant's resistances for the period that starts now (ResistanceDrift).
  void drift_resistances() noexcept;
  /// The brake's armature over the period that starts now, from its line and delays.
  void update_brake() noexcept;

  SimBoardConfig config_;
  InductionMotorPlant plant_;
  double Rs0_Ohm_, Rr0_Ohm_;  ///< the plant's resistances at t = 0
  AdcModel adc_model_;
  LoadProfile load_;
  mutable double load_time_s_ = std::numeric_limits<double>::quiet_NaN();  ///< kept for it
  mutable double load_at_time_Nm_ = 0.0;  ///< load_ at load_time_s_
  SimPwm pwm_;
  SimEncoder encoder_;
  SimAdc adc_;
  SimCan can_;
  SimGpio gpio_;
  SimTimer timer_;
  SimAnalogInnerLoop analog_;
  SimCurrentSource current_source_;
  hal::PhaseDuties active_duty_{0.5f, 0.5f, 0.5f};
  Vec2 active_analog_input_V_ = Vec2::Zero();
  Vec2 active_current_AB_A_ = Vec2::Zero();
  double start_torque_Nm_ = 0.0;
  Vec2 start_flux_s_alphabeta_Wb_ = Vec2::Zero();
  Vec2 start_current_alphabeta_A_ = Vec2::Zero();
  Vec2 applied_voltage_V_ = Vec2::Zero();
  bool brake_engaged_ = true;  ///< spring-applied: engaged until the line releases it
  uint32_t encoder_offset_counts_ = 0;  ///< counts lost while the encoder was frozen
  double brake_line_since_s_ = 0.0;  ///< the line's level has held since
  bool brake_line_released_ = false;
  double v_bus_V_;
  bool encoder_frozen_ = false;
  bool adc_stuck_ = false;
  std::size_t injected_count_ = 0;
};

}  // namespace imd::sim
