// The motor parameter record: field rules, the whole-record rule, and its stored form.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include "firmware/parameters/motor_record.hpp"
#include "tests/test_motors.hpp"

namespace {

using imd::control::MotorParameters;
using namespace imd::firmware;

TEST(MotorRecord, EveryTestMotorRoundTripsExactly) {
  for (const auto& motor : imd::test::test_motors()) {
    const auto bytes = encode_motor_record(motor.parameters);
    const auto back = decode_motor_record(bytes);
    ASSERT_TRUE(back.has_value()) << motor.name;
    for (int i = 0; i < kMotorFieldCount; ++i) {
      const auto f = static_cast<MotorField>(i);
      EXPECT_EQ(field_value(*back, f), field_value(motor.parameters, f)) << motor.name << " " << i;
    }
  }
}

TEST(MotorRecord, TheNameplateTravelsWithTheMotorAndMayBeMissing) {
  MotorRecord r(imd::test::test_motors().front().parameters);
  EXPECT_EQ(decode_motor_record(encode_motor_record(r))->nameplate.rated_voltage_V, 0.0);
  r.nameplate = {400.0, 1.9, 50.0, r.motor.pole_pairs};
  const auto back = decode_motor_record(encode_motor_record(r));
  ASSERT_TRUE(back.has_value());
  EXPECT_EQ(back->nameplate.rated_voltage_V, 400.0);
  // Exactly the value written, in the design arithmetic (float on the MCU).
  EXPECT_EQ(back->nameplate.rated_current_A, imd::Real(1.9));
  EXPECT_EQ(back->nameplate.rated_frequency_Hz, 50.0);
  EXPECT_EQ(field_value(*back, MotorField::rated_current_A), imd::Real(1.9));
  r.nameplate.rated_current_A = -1.0;  // a nameplate value is positive when given
  EXPECT_FALSE(decode_motor_record(encode_motor_record(r)).has_value());
}

TEST(MotorRecord, FieldRules) {
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const double inf = std::numeric_limits<double>::infinity();
  EXPECT_EQ(check_field(MotorField::Rs_Ohm, 1.2), ParameterStatus::ok);
  EXPECT_EQ(check_field(MotorField::Rs_Ohm, nan), ParameterStatus::not_finite);
  EXPECT_EQ(check_field(MotorField::Lm_H, inf), ParameterStatus::not_finite);
  EXPECT_EQ(check_field(MotorField::Rr_Ohm, -1.0), ParameterStatus::not_positive);
  EXPECT_EQ(check_field(MotorField::J_kgm2, 0.0), ParameterStatus::not_positive);
  EXPECT_EQ(check_field(MotorField::friction_Nms, 0.0), ParameterStatus::ok);
  EXPECT_EQ(check_field(MotorField::friction_Nms, -1e-6), ParameterStatus::negative);
  EXPECT_EQ(check_field(MotorField::pole_pairs, 2.0), ParameterStatus::ok);
  EXPECT_EQ(check_field(MotorField::pole_pairs, 2.5), ParameterStatus::not_whole);
  EXPECT_EQ(check_field(MotorField::pole_pairs, 0.0), ParameterStatus::not_whole);
  EXPECT_EQ(check_field(MotorField::pole_pairs, kMaxPolePairs + 1.0), ParameterStatus::not_whole);
  EXPECT_EQ(check_field(MotorField::rated_voltage_V, 0.0), ParameterStatus::not_positive);
  EXPECT_EQ(check_field(MotorField::rated_frequency_Hz, 50.0), ParameterStatus::ok);
}

TEST(MotorRecord, CouplingRuleIsTheMotorFilesRule) {
  MotorParameters m = imd::test::test_motors().front().parameters;
  EXPECT_EQ(check_record(m), ParameterStatus::ok);
  m.Lm_H = std::sqrt(m.Ls_H * m.Lr_H);  // no leakage at all
  EXPECT_EQ(check_record(m), ParameterStatus::no_leakage);
  EXPECT_TRUE(imd::control::find_invalid_parameter(m).has_value());
}

TEST(MotorRecord, DecodeRefusesOtherVersionsLengthsAndInvalidRecords) {
  const MotorParameters m = imd::test::test_motors().front().parameters;
  auto bytes = encode_motor_record(m);
  EXPECT_FALSE(decode_motor_record(std::span<const uint8_t>(bytes).first(bytes.size() - 1)));
  for (const uint8_t version : {uint8_t(kMotorRecordVersion - 1), uint8_t(kMotorRecordVersion + 1)}) {
    auto other_version = bytes;
    other_version[0] = version;
    EXPECT_FALSE(decode_motor_record(other_version)) << int(version);
  }
  MotorParameters bad = m;
  bad.Rs_Ohm = -bad.Rs_Ohm;
  EXPECT_FALSE(decode_motor_record(encode_motor_record(bad)));
  bad = m;
  bad.Lm_H = bad.Ls_H + bad.Lr_H;
  EXPECT_FALSE(decode_motor_record(encode_motor_record(bad)));
}

}  // namespace
