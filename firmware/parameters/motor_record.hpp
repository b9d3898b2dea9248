#pragma once
/// The motor parameter record: what the drive starts from and what a commissioning run or a
/// CAN write changes. Its fields are numbered as on CAN (the parameter_access message's index,
/// docs/can/protocol.md); the stored form is versioned and little-endian, and the store frames
/// it with a sequence number and a CRC (hal/storage/stored_slot.hpp). A field is checked alone
/// when written (finite, sign, whole pole pairs) and the whole record by the same rules as a
/// motor file (control::find_invalid_parameter) once every field has a value.
#include <array>
#include <iterator>
#include <cstdint>
#include <optional>
#include <span>

#include "control/motor_parameters.hpp"
#include "control/real.hpp"
#include "firmware/identification/nameplate.hpp"
#include "firmware/protocol/messages.hpp"

namespace imd::firmware {

/// The record's fields, by their index on CAN: the motor's model (the first kMotorFieldCount),
/// then its nameplate, which a commissioning run starts from (pole_pairs is both).
enum class MotorField : uint8_t {
  Rs_Ohm,
  Ls_H,
  Lm_H,
  Rr_Ohm,
  Lr_H,
  J_kgm2,
  pole_pairs,
  friction_Nms,
  rated_voltage_V,  ///< line-to-line RMS
  rated_current_A,  ///< RMS
  rated_frequency_Hz,
};
inline constexpr int kMotorFieldCount = 8;
inline constexpr int kRecordFieldCount = 11;
static_assert(std::size(protocol::kMotorFieldValues) == kRecordFieldCount,
              "every field has its name in the protocol's value table");

/// What the drive stores: the motor's parameters and its nameplate (0 where not given).
struct MotorRecord {
  MotorRecord() = default;
  MotorRecord(const control::MotorParameters& m) noexcept : motor(m) {  // NOLINT: a record of it
    nameplate.pole_pairs = m.pole_pairs;
  }
  control::MotorParameters motor;
  Nameplate nameplate;
};
using control::kMaxPolePairs;

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

inline constexpr std::size_t kMotorRecordBytes = 4 + 8 * kRecordFieldCount;
inline constexpr uint16_t kMotorRecordVersion = 2;

/// A motor field (the first kMotorFieldCount) of the parameters.
Real field_value(const control::MotorParameters& motor, MotorField field) noexcept;
/// Sets a motor field; pole_pairs takes the value rounded (check_field first).
void set_field(control::MotorParameters& motor, MotorField field, Real value) noexcept;
/// Any field of the record.
Real field_value(const MotorRecord& record, MotorField field) noexcept;
void set_field(MotorRecord& record, MotorField field, Real value) noexcept;

/// The rule a single value breaks (ok if none). The field must be a valid index.
ParameterStatus check_field(MotorField field, Real value) noexcept;
/// The rule a whole record breaks, as a status: control::find_invalid_parameter's rules.
ParameterStatus check_record(const control::MotorParameters& motor) noexcept;

std::array<uint8_t, kMotorRecordBytes> encode_motor_record(const MotorRecord& record) noexcept;
/// The record in `bytes`, if its version and length are this firmware's and its motor is
/// valid (nameplate fields may be 0: not given).
std::optional<MotorRecord> decode_motor_record(std::span<const uint8_t> bytes) noexcept;

}  // namespace imd::firmware
