#pragma once
/// The one place where the drive is wired to the simulated board: its PWM, encoder, ADC and
/// CAN, a timer (the board's lock-step timer, or a real-time one), and the simulation-only
/// substitutes a scenario asks for: ideal sensors, the analog inner-loop circuit, the ideal
/// current source. The drive starts as a board does: from the motor record in its parameter
/// store (a simulated flash page pair), which holds the scenario's motor, or nothing. No heap:
/// the processor-in-the-loop image builds it too.
#include <optional>

#include "firmware/drive.hpp"
#include "firmware/parameters/motor_record.hpp"
#include "hal/storage/page_pair_store.hpp"
#include "hal_sim/drive/ideal_sensors.hpp"
#include "hal_sim/drive/paper_power_stages.hpp"
#include "hal_sim/sim_board.hpp"
#include "hal_sim/sim_flash_pages.hpp"

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
  /// `motor`: the record the board's store holds at power-up (none: an empty store, the drive
  /// waits for a record over CAN). `references`: the scenario's profile (unused when the
  /// config takes them from CAN). `timer`: the board's lock-step timer or a real-time one;
  /// `can`, `gpio`: the board's, a real bus and lines, or none. `store`: a parameter store of
  /// the host's (a file) instead of the board's flash; the drive loads from it, `motor` aside.
  /// `watchdog`, `reset_cause`: the processor's (the processor-in-the-loop image), or none.
  SimulatedDrive(SimBoard& board, const std::optional<firmware::MotorRecord>& motor,
                 const firmware::DriveConfig& config, const SimulatedParts& parts,
                 const firmware::ReferenceSource<T>* references, hal::ControlTimer& timer,
                 hal::CanBus* can, hal::Gpio* gpio = nullptr, hal::ParameterStore* store = nullptr,
                 hal::Watchdog* watchdog = nullptr,
                 hal::ResetCause reset_cause = hal::ResetCause::power_on)
      : ideal_(board, motor ? motor->motor : board.plant().motor(), config),
        analog_(board),
        current_source_(board),
        flash_store_(flash_),
        store_(store != nullptr ? *store : flash_store_),
        drive_(stored(store == nullptr ? motor : std::nullopt), config,
               {board.pwm(), board.encoder(), board.adc(), timer, can, gpio, &store_, watchdog,
                reset_cause},
               substitutes(parts, references)) {}

  firmware::Drive<T>& drive() noexcept { return drive_; }
  const firmware::Drive<T>& drive() const noexcept { return drive_; }
  /// The board's parameter flash (a test may cut its power).
  SimFlashPages& flash() noexcept { return flash_; }

 private:
  /// Writes `motor` to the board's store, then loads what the store holds: what the drive
  /// starts from is what a board would read after power-up.
  std::optional<firmware::MotorRecord> stored(
      const std::optional<firmware::MotorRecord>& motor) noexcept {
    if (motor) store_.save(firmware::encode_motor_record(*motor));
    std::array<uint8_t, firmware::kMotorRecordBytes> bytes{};
    const std::size_t n = store_.load(bytes);
    return firmware::decode_motor_record(std::span<const uint8_t>(bytes).first(n));
  }

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
  SimFlashPages flash_;
  hal::PagePairStore<firmware::kMotorRecordBytes> flash_store_;
  hal::ParameterStore& store_;
  firmware::Drive<T> drive_;
};

}  // namespace imd::sim
