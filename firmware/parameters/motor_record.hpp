#pragma once
/// The motor parameter record: what the drive starts from and what a commissioning run or a
/// CAN write changes. Its fields are numbered as on CAN (the parameter_access message's index,
/// docs/can/protocol.md); the stored form is versioned and little-endian, and the store frames
/// it with a sequence number and a CRC (hal/storage/stored_slot.hpp). A field is checked alone
/// when written (finite, sign, whole pole pairs) and the whole record by the same rules as a
/// motor file (control::find_invalid_parameter) once every field has a value.
#include <array>
#include <cstdint>
#include <optional>
#include <span>

#include "control/motor_parameters.hpp"

namespace imd::firmware {

/// The record's fields, by their index on CAN.
enum class MotorField : uint8_t {
  Rs_Ohm,
  Ls_H,
  Lm_H,
  Rr_Ohm,
  Lr_H,
  J_kgm2,
  pole_pairs,
  friction_Nms,
};
inline constexpr int kMotorFieldCount = 8;
inline constexpr int kMaxPolePairs = 32;

/// Why a parameter write was refused (the parameter_value message's status; 0 is accepted).
enum class ParameterStatus : uint8_t {
  ok,
  not_idle,        ///< written while the drive was not idle (or was applying the last write)
  unknown_field,   ///< no field of this index
  not_finite,      ///< NaN or infinite
  not_positive,    ///< must be > 0
  negative,        ///< must be >= 0 (friction)
  not_whole,       ///< pole pairs: a whole number 1..kMaxPolePairs
  no_leakage,      ///< Lm^2 >= Ls Lr: the record would have no leakage inductance
  not_set,         ///< read of a field that has no value yet (no record)
  store_failed,    ///< the save did not complete (the previous record stays)
  busy,            ///< a save or an identification is in progress
};
inline constexpr int kParameterStatusCount = 11;

inline constexpr std::size_t kMotorRecordBytes = 4 + 8 * kMotorFieldCount;
inline constexpr uint16_t kMotorRecordVersion = 1;

double field_value(const control::MotorParameters& motor, MotorField field) noexcept;
/// Sets a field; pole_pairs takes the value rounded (check_field first).
void set_field(control::MotorParameters& motor, MotorField field, double value) noexcept;

/// The rule a single value breaks (ok if none). The field must be a valid index.
ParameterStatus check_field(MotorField field, double value) noexcept;
/// The rule a whole record breaks, as a status: control::find_invalid_parameter's rules.
ParameterStatus check_record(const control::MotorParameters& motor) noexcept;

std::array<uint8_t, kMotorRecordBytes> encode_motor_record(
    const control::MotorParameters& motor) noexcept;
/// The record in `bytes`, if its version and length are this firmware's and it is valid.
std::optional<control::MotorParameters> decode_motor_record(
    std::span<const uint8_t> bytes) noexcept;

}  // namespace imd::firmware
