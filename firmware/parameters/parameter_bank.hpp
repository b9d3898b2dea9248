#pragma once
/// The motor record as the running drive holds it, and the hand-over between the tick, which
/// answers CAN parameter accesses, and the service loop (Drive::service), which does what must
/// not run in the tick: rebuilding the motor model from a new record, and saving it.
///
/// A write edits the staged record. It is refused, and changes nothing, when the drive is not
/// idle, when a request is still being served, when the value breaks its field's rule, or when
/// the record, complete with it, breaks the coupling rule (Lm^2 < Ls Lr). Once every field has a
/// value, an accepted write asks the service loop to apply the record. A save asks it to store
/// the record in use. The pending request is the only shared state: the tick sets it, the
/// service loop clears it (release/acquire), and while it is set the tick neither edits the
/// record nor uses the model.
#include <atomic>
#include <cstdint>
#include <optional>

#include "control/motor_parameters.hpp"
#include "firmware/parameters/motor_record.hpp"

namespace imd::firmware {

class ParameterBank {
 public:
  enum class Request : uint8_t { none, apply, save };

  /// `loaded`: the record read from storage at start-up (none: the drive waits for one).
  explicit ParameterBank(const std::optional<control::MotorParameters>& loaded) noexcept
      : staged_(loaded.value_or(control::MotorParameters{0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0, 0.0})),
        set_fields_(loaded ? kAllFields : 0u),
        saved_(loaded.has_value()) {}

  // --- tick side

  /// The staged value of a field (the one in use unless a write is being applied).
  ParameterStatus read(uint8_t field, double& value) const noexcept {
    if (field >= kMotorFieldCount) return ParameterStatus::unknown_field;
    if ((set_fields_ & (1u << field)) == 0) return ParameterStatus::not_set;
    value = field_value(staged_, static_cast<MotorField>(field));
    return ParameterStatus::ok;
  }

  /// `idle`: the drive may change its model now (idle or unconfigured).
  ParameterStatus write(uint8_t field, double value, bool idle) noexcept {
    if (field >= kMotorFieldCount) return ParameterStatus::unknown_field;
    if (!idle) return ParameterStatus::not_idle;
    if (busy()) return ParameterStatus::busy;
    const auto f = static_cast<MotorField>(field);
    if (const ParameterStatus s = check_field(f, value); s != ParameterStatus::ok) return s;
    control::MotorParameters candidate = staged_;
    set_field(candidate, f, value);
    const uint32_t fields = set_fields_ | (1u << field);
    if (fields == kAllFields) {
      if (const ParameterStatus s = check_record(candidate); s != ParameterStatus::ok) return s;
    }
    staged_ = candidate;
    set_fields_ = fields;
    saved_.store(false, std::memory_order_relaxed);
    apply_wanted_ = fields == kAllFields;
    return ParameterStatus::ok;
  }

  /// A write asked for the record to be applied; the drive lets go of its model, then calls
  /// request_apply (at the end of the tick, so that the service loop never builds a model the
  /// tick still uses).
  bool apply_wanted() const noexcept { return apply_wanted_; }
  void request_apply() noexcept {
    apply_wanted_ = false;
    request_.store(Request::apply, std::memory_order_release);
  }

  ParameterStatus save() noexcept {
    if (busy()) return ParameterStatus::busy;
    if (!complete()) return ParameterStatus::not_set;
    request_.store(Request::save, std::memory_order_release);
    return ParameterStatus::ok;
  }

  bool complete() const noexcept { return set_fields_ == kAllFields; }
  bool saved() const noexcept { return saved_.load(std::memory_order_relaxed); }
  /// The outcome of the last save the service loop completed, once (tick side).
  std::optional<ParameterStatus> take_outcome() noexcept {
    if (!outcome_ready_.load(std::memory_order_acquire)) return std::nullopt;
    outcome_ready_.store(false, std::memory_order_relaxed);
    return outcome_;
  }

  // --- both sides

  Request pending() const noexcept { return request_.load(std::memory_order_acquire); }
  bool busy() const noexcept { return apply_wanted_ || pending() != Request::none; }

  // --- service side (only while a request is pending)

  const control::MotorParameters& staged() const noexcept { return staged_; }
  /// The request is served. A save's outcome is answered on CAN by the tick (take_outcome);
  /// an apply was answered when its write was accepted, and shows as the state change.
  void complete_request(ParameterStatus outcome) noexcept {
    if (pending() == Request::save) {
      if (outcome == ParameterStatus::ok) saved_.store(true, std::memory_order_relaxed);
      outcome_ = outcome;
      outcome_ready_.store(true, std::memory_order_release);
    }
    request_.store(Request::none, std::memory_order_release);
  }

 private:
  static constexpr uint32_t kAllFields = (1u << kMotorFieldCount) - 1;

  control::MotorParameters staged_;
  uint32_t set_fields_;
  std::atomic<bool> saved_;
  bool apply_wanted_ = false;  ///< tick side only
  std::atomic<Request> request_{Request::none};
  ParameterStatus outcome_ = ParameterStatus::ok;
  std::atomic<bool> outcome_ready_{false};
};

}  // namespace imd::firmware
