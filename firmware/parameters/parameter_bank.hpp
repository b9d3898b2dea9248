#pragma once
/// The motor record as the running drive holds it, and the hand-over between the tick, which
/// receives CAN parameter accesses and answers them, and the service loop (Drive::service),
/// which does the work: checking a value against the record's rules (in Real: float on the MCU),
/// saving the record, and rebuilding the motor model. None of that runs in the tick.
///
/// One access at a time goes through these stages:
///   free -> access (the tick submits it) -> answered (the service loop served it)
///        -> free, or -> apply (a write completed a valid record: the tick has let go of the
///           model, the service loop builds the new one) -> free.
/// The stage is the only shared state: whoever moves it on publishes what it wrote (release)
/// and the other side reads it after (acquire). A write is refused, and changes nothing, when
/// the drive is not idle, when the value breaks its field's rule, or when the record, complete
/// with it, breaks the coupling rule (Lm^2 < Ls Lr).
#include <atomic>
#include <cstdint>
#include <optional>

#include "control/motor_parameters.hpp"
#include "control/real.hpp"
#include "firmware/parameters/motor_record.hpp"
#include "firmware/protocol/commands.hpp"
#include "hal/parameter_store.hpp"

namespace imd::firmware {

struct ParameterAccess {
  protocol::ParameterOp op = protocol::ParameterOp::read;
  uint8_t field = 0;
  float value = 0.0f;  ///< write
  bool at_rest = false;  ///< the drive was idle or unconfigured when the write arrived
};

struct ParameterAnswer {
  ParameterAccess access;
  ParameterStatus status = ParameterStatus::ok;
  float value = 0.0f;     ///< the field after the access (NaN: no value)
  bool complete = false;  ///< every field has a valid value
  bool saved = false;     ///< the record in use is the one in storage
  bool apply = false;     ///< the record changed: the drive must rebuild its model
};

class ParameterBank {
 public:
  enum class Stage : uint8_t { free, access, answered, apply };

  /// `loaded`: the record read from storage at start-up (none: the drive waits for one).
  explicit ParameterBank(const std::optional<MotorRecord>& loaded) noexcept;

  // --- tick side

  /// Queues an access; false while another one is in progress (answer it busy).
  bool submit(const ParameterAccess& access) noexcept;
  /// The answer, once served; the bank is free again unless the answer asks for a new model
  /// (then the drive calls request_apply once it has let go of the old one).
  std::optional<ParameterAnswer> take_answer() noexcept;
  bool apply_wanted() const noexcept { return apply_wanted_; }
  void request_apply() noexcept;
  bool busy() const noexcept { return apply_wanted_ || stage() != Stage::free; }

  // --- both sides

  Stage stage() const noexcept { return stage_.load(std::memory_order_acquire); }

  // --- service side

  /// Serves a submitted access (reads, checks and stages a write, saves to `store`).
  void serve(hal::ParameterStore* store) noexcept;
  /// The motor the new model is built from (stage apply), then frees the bank.
  const control::MotorParameters& staged() const noexcept { return staged_.motor; }
  void applied() noexcept { stage_.store(Stage::free, std::memory_order_release); }
  /// Outside the tick: the motor, if its record is complete.
  std::optional<control::MotorParameters> record() const noexcept;
  /// Outside the tick: the nameplate, if every field of it has a value.
  std::optional<Nameplate> nameplate() const noexcept;
  /// The access being served (stage access).
  const ParameterAccess& access() const noexcept { return access_; }
  /// Answers the access with `status` without serving it here (the drive's own requests).
  void answer(ParameterStatus status) noexcept;
  /// A whole new motor (a commissioning's result): checked, staged and saved. The nameplate
  /// stays.
  ParameterStatus adopt(const control::MotorParameters& motor, hal::ParameterStore* store) noexcept;

 private:
  static constexpr uint32_t kMotorFields = (1u << kMotorFieldCount) - 1;
  static constexpr uint32_t kNameplateFields =
      ((1u << kRecordFieldCount) - 1 - kMotorFields) | (1u << int(MotorField::pole_pairs));
  bool complete() const noexcept { return (set_fields_ & kMotorFields) == kMotorFields; }
  ParameterStatus read(uint8_t field, Real& value) const noexcept;
  ParameterStatus write(uint8_t field, Real value, bool at_rest, bool& changed) noexcept;

  MotorRecord staged_;
  uint32_t set_fields_;
  bool saved_;
  ParameterAccess access_;  ///< written by the tick (stage free -> access)
  ParameterAnswer answer_;  ///< written by the service loop (access -> answered)
  std::atomic<Stage> stage_{Stage::free};
  bool apply_wanted_ = false;  ///< tick side only
};

}  // namespace imd::firmware
