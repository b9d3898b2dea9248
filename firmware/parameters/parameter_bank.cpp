#include "firmware/parameters/parameter_bank.hpp"

#include <limits>

namespace imd::firmware {

namespace {
/// The fields of a loaded record that have values: the motor's all, the nameplate's if given.
uint32_t fields_of(const std::optional<MotorRecord>& loaded) noexcept {
  if (!loaded) return 0u;
  uint32_t fields = (1u << kMotorFieldCount) - 1;
  for (int i = kMotorFieldCount; i < kRecordFieldCount; ++i) {
    if (field_value(*loaded, MotorField(i)) > 0) fields |= 1u << i;
  }
  return fields;
}

MotorRecord empty_record() noexcept {
  MotorRecord r;
  r.motor = control::MotorParameters{0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0, 0.0};
  r.nameplate = Nameplate{};
  return r;
}
}  // namespace

ParameterBank::ParameterBank(const std::optional<MotorRecord>& loaded) noexcept
    : staged_(loaded.value_or(empty_record())),
      set_fields_(fields_of(loaded)),
      saved_(loaded.has_value()) {}

bool ParameterBank::submit(const ParameterAccess& access) noexcept {
  if (busy()) return false;
  access_ = access;
  stage_.store(Stage::access, std::memory_order_release);
  return true;
}

std::optional<ParameterAnswer> ParameterBank::take_answer() noexcept {
  if (stage() != Stage::answered) return std::nullopt;
  const ParameterAnswer answer = answer_;
  apply_wanted_ = answer.apply;
  if (!apply_wanted_) stage_.store(Stage::free, std::memory_order_release);
  return answer;
}

void ParameterBank::request_apply() noexcept {
  apply_wanted_ = false;
  stage_.store(Stage::apply, std::memory_order_release);
}

std::optional<control::MotorParameters> ParameterBank::record() const noexcept {
  if (!complete()) return std::nullopt;
  return staged_.motor;
}

std::optional<Nameplate> ParameterBank::nameplate() const noexcept {
  if ((set_fields_ & kNameplateFields) != kNameplateFields) return std::nullopt;
  return staged_.nameplate;
}

ParameterStatus ParameterBank::read(uint8_t field, Real& value) const noexcept {
  if (field >= kRecordFieldCount) return ParameterStatus::unknown_field;
  if ((set_fields_ & (1u << field)) == 0) return ParameterStatus::not_set;
  value = field_value(staged_, static_cast<MotorField>(field));
  return ParameterStatus::ok;
}

ParameterStatus ParameterBank::write(uint8_t field, Real value, bool at_rest,
                                     bool& changed) noexcept {
  changed = false;
  if (field >= kRecordFieldCount) return ParameterStatus::unknown_field;
  if (!at_rest) return ParameterStatus::not_idle;
  const auto f = static_cast<MotorField>(field);
  if (const ParameterStatus s = check_field(f, value); s != ParameterStatus::ok) return s;
  MotorRecord candidate = staged_;
  set_field(candidate, f, value);
  const uint32_t fields = set_fields_ | (1u << field);
  const bool motor_complete = (fields & kMotorFields) == kMotorFields;
  if (motor_complete) {
    if (const ParameterStatus s = check_record(candidate.motor); s != ParameterStatus::ok) {
      return s;
    }
  }
  staged_ = candidate;
  set_fields_ = fields;
  saved_ = false;
  // Only the motor's fields make a new model; the nameplate is for the next commissioning.
  changed = motor_complete && field < kMotorFieldCount;
  return ParameterStatus::ok;
}

void ParameterBank::answer(ParameterStatus status) noexcept {
  ParameterAnswer a;
  a.access = access_;
  a.status = status;
  a.value = std::numeric_limits<float>::quiet_NaN();
  a.complete = complete();
  a.saved = saved_;
  answer_ = a;
  stage_.store(Stage::answered, std::memory_order_release);
}

ParameterStatus ParameterBank::adopt(const control::MotorParameters& motor,
                                     hal::ParameterStore* store) noexcept {
  if (const ParameterStatus s = check_record(motor); s != ParameterStatus::ok) return s;
  staged_.motor = motor;
  staged_.nameplate.pole_pairs = motor.pole_pairs;
  set_fields_ |= kMotorFields;
  saved_ = store != nullptr && store->save(encode_motor_record(staged_));
  return saved_ ? ParameterStatus::ok : ParameterStatus::store_failed;
}

void ParameterBank::serve(hal::ParameterStore* store) noexcept {
  if (stage() != Stage::access) return;
  ParameterAnswer a;
  a.access = access_;
  switch (access_.op) {
    case protocol::ParameterOp::read:
      break;
    case protocol::ParameterOp::write:
      a.status = write(access_.field, Real(access_.value), access_.at_rest, a.apply);
      break;
    case protocol::ParameterOp::identify:
    case protocol::ParameterOp::identified:
      a.status = ParameterStatus::busy;  // the drive's own requests: Drive::service serves them
      break;
    case protocol::ParameterOp::save:
      if (!complete()) {
        a.status = ParameterStatus::not_set;
      } else if (store == nullptr || !store->save(encode_motor_record(staged_))) {
        a.status = ParameterStatus::store_failed;
      } else {
        saved_ = true;
      }
      break;
  }
  Real value = std::numeric_limits<Real>::quiet_NaN();
  const ParameterStatus read_status = read(access_.field, value);
  if (access_.op == protocol::ParameterOp::read) a.status = read_status;
  a.value = read_status == ParameterStatus::ok ? static_cast<float>(value)
                                               : std::numeric_limits<float>::quiet_NaN();
  a.complete = complete();
  a.saved = saved_;
  answer_ = a;
  stage_.store(Stage::answered, std::memory_order_release);
}

}  // namespace imd::firmware
