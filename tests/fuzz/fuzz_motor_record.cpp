// libFuzzer harness: bytes into decode_motor_record, the parameter record the board keeps in
// flash (firmware/parameters/motor_record.hpp). Whatever the bytes, the decoder must return
// nothing or a record whose motor is valid and which encodes back to bytes that decode to the
// same record.
//
// Input: byte 0 bit 0 clear: the rest is the record's bytes as they are. Set: the rest is a
// list of (position, value) pairs written over a valid record (the paper-000 motor), so that
// the fuzzer works near records that pass the version, length and range checks.
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <span>

#include "control/motor_parameters.hpp"
#include "firmware/parameters/motor_record.hpp"
#include "fuzz_check.hpp"
#include "tests/firmware/paper_motor.hpp"

namespace firmware = imd::firmware;

namespace {

std::optional<firmware::MotorRecord> decode(std::span<const uint8_t> bytes) {
  return firmware::decode_motor_record(bytes);
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  if (size < 1) return 0;
  std::optional<firmware::MotorRecord> record;
  if ((data[0] & 1) == 0) {
    record = decode({data + 1, size - 1});
  } else {
    auto bytes = firmware::encode_motor_record(firmware::MotorRecord(imd::test::paper_motor()));
    for (size_t i = 1; i + 1 < size; i += 2) bytes[data[i] % bytes.size()] = data[i + 1];
    record = decode(bytes);
  }
  if (!record) return 0;
  FUZZ_CHECK(!imd::control::find_invalid_parameter(record->motor).has_value());
  const auto bytes = firmware::encode_motor_record(*record);
  const std::optional<firmware::MotorRecord> again = decode(bytes);
  FUZZ_CHECK(again.has_value());
  const auto bytes_again = firmware::encode_motor_record(*again);
  FUZZ_CHECK(std::memcmp(bytes.data(), bytes_again.data(), bytes.size()) == 0);
  return 0;
}
