#include "firmware/parameters/motor_record.hpp"

#include <cmath>

#include "firmware/parameters/binary64.hpp"

namespace imd::firmware {

Real field_value(const control::MotorParameters& m, MotorField field) noexcept {
  switch (field) {
    case MotorField::Rs_Ohm: return m.Rs_Ohm;
    case MotorField::Ls_H: return m.Ls_H;
    case MotorField::Lm_H: return m.Lm_H;
    case MotorField::Rr_Ohm: return m.Rr_Ohm;
    case MotorField::Lr_H: return m.Lr_H;
    case MotorField::J_kgm2: return m.J_kgm2;
    case MotorField::pole_pairs:
      return Real(m.pole_pairs);
    case MotorField::friction_Nms: return m.friction_Nms;
    default: return 0.0;
  }
}

void set_field(control::MotorParameters& m, MotorField field, Real value) noexcept {
  switch (field) {
    case MotorField::Rs_Ohm: m.Rs_Ohm = value; break;
    case MotorField::Ls_H: m.Ls_H = value; break;
    case MotorField::Lm_H: m.Lm_H = value; break;
    case MotorField::Rr_Ohm: m.Rr_Ohm = value; break;
    case MotorField::Lr_H: m.Lr_H = value; break;
    case MotorField::J_kgm2: m.J_kgm2 = value; break;
    case MotorField::pole_pairs: m.pole_pairs = static_cast<int>(std::lround(value)); break;
    case MotorField::friction_Nms: m.friction_Nms = value; break;
    default: break;
  }
}

Real field_value(const MotorRecord& r, MotorField field) noexcept {
  switch (field) {
    case MotorField::rated_voltage_V: return r.nameplate.rated_voltage_V;
    case MotorField::rated_current_A: return r.nameplate.rated_current_A;
    case MotorField::rated_frequency_Hz: return r.nameplate.rated_frequency_Hz;
    default: return field_value(r.motor, field);
  }
}

void set_field(MotorRecord& r, MotorField field, Real value) noexcept {
  switch (field) {
    case MotorField::rated_voltage_V: r.nameplate.rated_voltage_V = value; break;
    case MotorField::rated_current_A: r.nameplate.rated_current_A = value; break;
    case MotorField::rated_frequency_Hz: r.nameplate.rated_frequency_Hz = value; break;
    case MotorField::pole_pairs:
      set_field(r.motor, field, value);
      r.nameplate.pole_pairs = r.motor.pole_pairs;
      break;
    default: set_field(r.motor, field, value); break;
  }
}

ParameterStatus check_field(MotorField field, Real value) noexcept {
  if (!std::isfinite(value)) return ParameterStatus::not_finite;
  if (field == MotorField::friction_Nms) {
    return value < 0 ? ParameterStatus::negative : ParameterStatus::ok;
  }
  if (field == MotorField::pole_pairs) {
    return value == std::round(value) && value >= 1 && value <= kMaxPolePairs
               ? ParameterStatus::ok
               : ParameterStatus::not_whole;
  }
  return value > 0 ? ParameterStatus::ok : ParameterStatus::not_positive;
}

ParameterStatus check_record(const control::MotorParameters& motor) noexcept {
  for (int i = 0; i < kMotorFieldCount; ++i) {
    const auto field = static_cast<MotorField>(i);
    const ParameterStatus s = check_field(field, field_value(motor, field));
    if (s != ParameterStatus::ok) return s;
  }
  // The coupling rule is the last of find_invalid_parameter's, after those checked above.
  return control::find_invalid_parameter(motor) ? ParameterStatus::no_leakage
                                                : ParameterStatus::ok;
}

std::array<uint8_t, kMotorRecordBytes> encode_motor_record(const MotorRecord& record) noexcept {
  std::array<uint8_t, kMotorRecordBytes> out{};
  out[0] = static_cast<uint8_t>(kMotorRecordVersion);
  out[1] = static_cast<uint8_t>(kMotorRecordVersion >> 8);
  out[2] = kRecordFieldCount;
  out[3] = 0;
  for (int i = 0; i < kRecordFieldCount; ++i) {
    const uint64_t bits = record_bits(field_value(record, static_cast<MotorField>(i)));
    for (int b = 0; b < 8; ++b) out[4 + 8 * i + b] = static_cast<uint8_t>(bits >> (8 * b));
  }
  return out;
}

std::optional<MotorRecord> decode_motor_record(std::span<const uint8_t> bytes) noexcept {
  if (bytes.size() != kMotorRecordBytes) return std::nullopt;
  const uint16_t version = static_cast<uint16_t>(bytes[0] | bytes[1] << 8);
  if (version != kMotorRecordVersion || bytes[2] != kRecordFieldCount) return std::nullopt;
  MotorRecord record;
  for (int i = 0; i < kRecordFieldCount; ++i) {
    uint64_t bits = 0;
    for (int b = 0; b < 8; ++b) bits |= uint64_t(bytes[4 + 8 * i + b]) << (8 * b);
    const Real v = record_value(bits);
    const auto field = static_cast<MotorField>(i);
    const bool unset_nameplate = i >= kMotorFieldCount && v == 0;
    if (!unset_nameplate && check_field(field, v) != ParameterStatus::ok) return std::nullopt;
    set_field(record, field, v);
  }
  if (check_record(record.motor) != ParameterStatus::ok) return std::nullopt;
  return record;
}

}  // namespace imd::firmware
