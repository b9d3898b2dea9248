#pragma once
/// The one place where the drive is wired to the simulated board: its PWM, encoder, ADC and
/// CAN, a timer (the board's lock-step timer, or a real-time one), and the simulation-only
/// substitutes a scenario asks for: ideal sensors, the analog inner-loop circuit, the ideal
/// current source. No heap: the processor-in-the-loop image builds it too.
#include "firmware/drive.hpp"
#include "hal_sim/drive/ideal_sensors.hpp"
#include "hal_sim/drive/paper_power_stages.hpp"
#include "hal_sim/sim_board.hpp"

namespace imd::sim {

/// Which of the simulated board's devices stand in for the drive's own parts.
struct SimulatedParts {
  bool ideal_sensors = false;
  InnerFeedback inner_feedback = InnerFeedback::digital;
  bool current_source = false;  ///< the ideal current source drives the motor
};

template <typename T>
class SimulatedDrive {
 public:
  /// `references`: the scenario's profile (unused when the config takes them from CAN).
  /// `timer`: the board's lock-step timer or a real-time one; `can`, `gpio`: the board's, a
  /// real bus and lines, or none.
  SimulatedDrive(SimBoard& board, const control::MotorParameters& motor,
                 const firmware::DriveConfig& config, const SimulatedParts& parts,
                 const firmware::ReferenceSource<T>* references, hal::ControlTimer& timer,
                 hal::CanBus* can, hal::Gpio* gpio = nullptr)
      : ideal_(board, motor, config),
        analog_(board),
        current_source_(board),
        drive_(motor, config, {board.pwm(), board.encoder(), board.adc(), timer, can, gpio},
               substitutes(parts, references)) {}

  firmware::Drive<T>& drive() noexcept { return drive_; }
  const firmware::Drive<T>& drive() const noexcept { return drive_; }

 private:
  firmware::DriveSubstitutes<T> substitutes(const SimulatedParts& parts,
                                            const firmware::ReferenceSource<T>* references) {
    firmware::DriveSubstitutes<T> s;
    s.references = references;
    if (parts.ideal_sensors) s.sensing = &ideal_, s.estimator = &ideal_;
    if (parts.current_source) {
      s.power_stage = &current_source_;
    } else if (parts.inner_feedback == InnerFeedback::ideal_analog) {
      s.power_stage = &analog_;
    }
    return s;
  }

  IdealSensors<T> ideal_;
  AnalogInnerLoopStage<T> analog_;
  CurrentSourceStage<T> current_source_;
  firmware::Drive<T> drive_;
};

}  // namespace imd::sim
