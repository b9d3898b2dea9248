// The CAN protocol table, signal packing, the E2E CRC and the command decoder's rejections.
#include <gtest/gtest.h>

#include <bit>
#include <cmath>
#include <limits>
#include <random>
#include <set>
#include <string>
#include <vector>

#include "firmware/protocol/commands.hpp"
#include "firmware/protocol/e2e.hpp"
#include "firmware/protocol/frame_codec.hpp"

namespace imd::firmware::protocol {
namespace {

TEST(Crc8, MatchesTheSaeJ1850CheckValue) {
  // CRC-8/SAE-J1850 (poly 0x1D, init 0xFF, xorout 0xFF) of "123456789" is 0x4B.
  const uint8_t text[] = {'1', '2', '3', '4', '5', '6', '7', '8', '9'};
  EXPECT_EQ(crc8_sae_j1850(text, 9) ^ 0xFF, 0x4B);
}

TEST(MessageTable, IdsAreUniqueAndSignalsFitTheirFrame) {
  std::set<int> ids;
  for (const Message& m : kMessages) {
    EXPECT_TRUE(ids.insert(int(m.id)).second) << m.name;
    EXPECT_LT(int(m.id), 32) << m.name;
    EXPECT_LE(m.length, 8) << m.name;
    uint64_t used = 0;
    for (const Signal& s : m.signals) {
      EXPECT_LE(s.start_bit + s.length_bits, 8 * m.length) << m.name << "." << s.name;
      const uint64_t bits = ((uint64_t(1) << s.length_bits) - 1) << s.start_bit;
      EXPECT_EQ(used & bits, 0u) << m.name << "." << s.name << " overlaps";
      used |= bits;
    }
    if (m.e2e()) {
      ASSERT_GE(m.signals.size(), 2u);
      EXPECT_STREQ(m.signals[0].name, "crc");
      EXPECT_STREQ(m.signals[1].name, "counter");
    }
  }
}

TEST(SignalPacking, RoundTripsSignedValuesAndSaturates) {
  const Signal& speed = kSpeedFluxSignals[0];  // int16, 0.01 rad/s
  Payload data{};
  set_physical(data, speed, -123.45f);
  EXPECT_EQ(get_raw(data, speed), -12345);
  EXPECT_NEAR(get_physical(data, speed), -123.45f, 0.005f);
  set_physical(data, speed, 1e6f);
  EXPECT_EQ(get_raw(data, speed), 32767);
  set_physical(data, speed, std::nanf(""));
  EXPECT_EQ(get_raw(data, speed), -32768);  // NaN never looks like a plausible value
  // Neighbours are untouched.
  set_physical(data, kSpeedFluxSignals[1], 7.0f);
  EXPECT_EQ(get_raw(data, speed), -32768);
  EXPECT_EQ(get_raw(data, kSpeedFluxSignals[1]), 700);
}

// The packing rounds without the library's roundf: for every float it must give std::round's
// value (a zero's sign aside, which no raw value keeps). Halves and their float neighbours at
// every magnitude below 2^23, where the fraction is kept, then random bit patterns.
TEST(SignalPacking, RoundHalfAwayIsStdRound) {
  const auto same = [](float x) {
    const float expected = std::round(x), got = round_half_away(x);
    if (std::isnan(expected)) return std::isnan(got);
    return got == expected;  // +0 == -0
  };
  for (const float x : {0.0f, -0.0f, 0.49999997f, -0.49999997f, 8388607.5f, -8388607.5f,
                        8388608.0f, 16777217.0f, 3.0e38f, std::numeric_limits<float>::infinity(),
                        -std::numeric_limits<float>::infinity(), std::nanf(""),
                        std::numeric_limits<float>::denorm_min()}) {
    EXPECT_TRUE(same(x)) << x;
  }
  for (int e = -24; e <= 23; ++e) {
    for (const float whole : {0.0f, std::ldexp(1.0f, e), std::ldexp(1.5f, e)}) {
      const float half = std::floor(whole) + 0.5f;
      float x = half, y = half;
      for (int ulp = 0; ulp < 4; ++ulp) {
        EXPECT_TRUE(same(x) && same(-x) && same(y) && same(-y)) << x << " " << y;
        x = std::nextafter(x, 0.0f);
        y = std::nextafter(y, 1e30f);
      }
    }
  }
  std::mt19937 bits(20261127);
  for (int i = 0; i < 2'000'000; ++i) {
    const float x = std::bit_cast<float>(static_cast<uint32_t>(bits()));
    ASSERT_TRUE(same(x)) << std::bit_cast<uint32_t>(x);
  }
}

// to_raw compares with the signal's limits converted from 32-bit integers: the raw values must
// be those of the 64-bit conversions and std::round, for every signal of the table, over its
// whole physical range and past it (saturation), at its edges, and for NaN and infinities;
// in_range likewise.
TEST(SignalPacking, ToRawMatchesTheDoubleWidthReference) {
  const auto reference = [](const Signal& s, float value) -> int64_t {
    const float raw = std::round((value - s.offset) * float(s.scale_den) / float(s.scale_num));
    if (!(raw >= float(s.raw_min()))) return s.raw_min();
    if (raw >= float(s.raw_max())) return s.raw_max();
    return static_cast<int64_t>(raw);
  };
  const auto reference_in_range = [](const Signal& s, float value) {
    const float raw = std::round((value - s.offset) * float(s.scale_den) / float(s.scale_num));
    return raw >= float(s.raw_min()) && raw <= float(s.raw_max());
  };
  std::mt19937 draw(7);
  for (const Message& m : kMessages) {
    for (const Signal& s : m.signals) {
      if (s.is_float) continue;
      const float lo = float(double(s.raw_min()) * s.scale() + s.offset);
      const float hi = float(double(s.raw_max()) * s.scale() + s.offset);
      std::uniform_real_distribution<float> value(lo - (hi - lo), hi + (hi - lo));
      std::vector<float> values = {lo, hi, std::nextafter(lo, -1e30f), std::nextafter(hi, 1e30f),
                                   std::nextafter(lo, hi), std::nextafter(hi, lo),
                                   0.0f, std::nanf(""), std::numeric_limits<float>::infinity(),
                                   -std::numeric_limits<float>::infinity()};
      for (int i = 0; i < 20'000; ++i) values.push_back(value(draw));
      for (const float v : values) {
        const std::string where = std::string(m.name) + "." + s.name;
        ASSERT_EQ(to_raw(s, v), reference(s, v)) << where << " at " << v;
        ASSERT_EQ(in_range(s, v), reference_in_range(s, v)) << where << " at " << v;
      }
    }
  }
}

TEST(SignalPacking, NodeAndMessageFormTheIdentifier) {
  EXPECT_EQ(can_id(1, MessageId::heartbeat), 0x22);
  EXPECT_EQ(can_id(63, MessageId::timing), 63 * 32 + 0x13);
  EXPECT_EQ(node_of(can_id(5, MessageId::set_speed)), 5);
  EXPECT_EQ(message_of(can_id(5, MessageId::set_speed)), 0x07);
}

class Decoder : public ::testing::Test {
 protected:
  CommandDecoder decoder{1, CommandLimits{100.0f, 0.01f, 1.0f}};
  CommandEncoder encoder{1};
};

TEST_F(Decoder, AcceptsAValidSequence) {
  const Decoded a = decoder.decode(encoder.encode({CommandKind::set_speed, 50.0f}));
  ASSERT_EQ(a.result, CommandResult::accepted);
  EXPECT_EQ(a.command.kind, CommandKind::set_speed);
  EXPECT_NEAR(a.command.value, 50.0f, 1e-3f);
  const Decoded b = decoder.decode(encoder.encode({CommandKind::enable}));
  EXPECT_EQ(b.result, CommandResult::accepted);
  EXPECT_EQ(b.counter, 1);
  EXPECT_EQ(decoder.last_counter(), 1);
  EXPECT_EQ(decoder.rejected_total(), 0u);
}

// The value travels as an IEEE single, exactly, NaN and infinities included: the drive judges
// it and answers with its reason (tests/firmware/test_drive_parameters.cpp).
TEST_F(Decoder, ParameterAccessCarriesOpFieldAndTheExactFloat) {
  for (const float value : {0.377f, 1e-7f, -14.0f, std::numeric_limits<float>::quiet_NaN(),
                            std::numeric_limits<float>::infinity()}) {
    const Decoded d = decoder.decode(
        encoder.encode({CommandKind::parameter_access, value, ParameterOp::write, 7}));
    ASSERT_EQ(d.result, CommandResult::accepted) << value;
    EXPECT_EQ(d.command.kind, CommandKind::parameter_access);
    EXPECT_EQ(d.command.op, ParameterOp::write);
    EXPECT_EQ(d.command.field, 7);
    EXPECT_EQ(std::bit_cast<uint32_t>(d.command.value), std::bit_cast<uint32_t>(value));
  }
}

TEST_F(Decoder, RejectsAParameterOpTheProtocolDoesNotDefine) {
  hal::CanFrame f = encoder.encode({CommandKind::parameter_access, 1.0f, ParameterOp::save, 0});
  f.data[1] = static_cast<uint8_t>((f.data[1] & 0x0F) | (kParameterOpCount << 4));
  f.data[0] = e2e_crc(f.id, f.data, f.length);
  EXPECT_EQ(decoder.decode(f).result, CommandResult::out_of_range);
}

TEST_F(Decoder, CounterWrapsAroundSixteen) {
  for (int i = 0; i < 40; ++i) {
    EXPECT_EQ(decoder.decode(encoder.encode({CommandKind::enable})).result, CommandResult::accepted)
        << i;
  }
}

TEST_F(Decoder, RejectsABadCrcAndChangesNothing) {
  ASSERT_EQ(decoder.decode(encoder.encode({CommandKind::enable})).result, CommandResult::accepted);
  hal::CanFrame f = encoder.encode({CommandKind::set_speed, 10.0f});
  f.data[3] ^= 0x01;  // one payload bit flipped on the wire
  EXPECT_EQ(decoder.decode(f).result, CommandResult::bad_crc);
  EXPECT_EQ(decoder.rejected(CommandResult::bad_crc), 1u);
  EXPECT_EQ(decoder.last_counter(), 0);  // the counter did not advance
}

TEST_F(Decoder, RejectsAFrameMeantForAnotherMessage) {
  // The same payload moved to another identifier fails the CRC: the id is part of it.
  hal::CanFrame f = encoder.encode({CommandKind::disable});
  f.id = can_id(1, MessageId::enable);
  EXPECT_EQ(decoder.decode(f).result, CommandResult::bad_crc);
}

TEST_F(Decoder, RejectsARepeatedCounter) {
  const hal::CanFrame f = encoder.encode({CommandKind::enable});
  EXPECT_EQ(decoder.decode(f).result, CommandResult::accepted);
  EXPECT_EQ(decoder.decode(f).result, CommandResult::repeated_counter);
  EXPECT_EQ(decoder.rejected(CommandResult::repeated_counter), 1u);
}

TEST_F(Decoder, RejectsAStaleCounter) {
  EXPECT_EQ(decoder.decode(encoder.encode({CommandKind::enable})).result, CommandResult::accepted);
  encoder.set_next_counter(0 + kMaxCounterStep + 1);  // more frames lost than allowed
  EXPECT_EQ(decoder.decode(encoder.encode({CommandKind::enable})).result,
            CommandResult::stale_counter);
  encoder.set_next_counter(15);  // one behind: a replayed frame
  EXPECT_EQ(decoder.decode(encoder.encode({CommandKind::enable})).result,
            CommandResult::stale_counter);
  encoder.set_next_counter(kMaxCounterStep);  // the largest step allowed
  EXPECT_EQ(decoder.decode(encoder.encode({CommandKind::enable})).result, CommandResult::accepted);
}

TEST_F(Decoder, RejectsAWrongLength) {
  hal::CanFrame f = encoder.encode({CommandKind::set_speed, 1.0f});
  f.length = 5;
  EXPECT_EQ(decoder.decode(f).result, CommandResult::wrong_length);
  f.length = 8;
  EXPECT_EQ(decoder.decode(f).result, CommandResult::wrong_length);
}

TEST_F(Decoder, RejectsOutOfRangeValues) {
  EXPECT_EQ(decoder.decode(encoder.encode({CommandKind::set_speed, 100.5f})).result,
            CommandResult::out_of_range);
  EXPECT_EQ(decoder.decode(encoder.encode({CommandKind::set_flux, 0.005f})).result,
            CommandResult::out_of_range);  // below the 0.01 Wb^2 floor
  EXPECT_EQ(decoder.decode(encoder.encode({CommandKind::set_flux, 1.5f})).result,
            CommandResult::out_of_range);
  EXPECT_EQ(decoder.decode(encoder.encode({CommandKind::select_controller, 3.0f})).result,
            CommandResult::out_of_range);  // the laws are 0 (dsmc), 1 (iol), 2 (ifoc)
  EXPECT_EQ(decoder.decode(encoder.encode({CommandKind::set_telemetry_rate, 5.0f})).result,
            CommandResult::out_of_range);
  EXPECT_EQ(decoder.decode(encoder.encode({CommandKind::set_telemetry_rate, 1001.0f})).result,
            CommandResult::out_of_range);
  EXPECT_EQ(decoder.rejected(CommandResult::out_of_range), 6u);
  // Each refused frame passed the E2E checks, so the reference followed the host's counter:
  // the next frame in sequence is accepted, and the last refused counter cannot be replayed.
  EXPECT_EQ(decoder.last_counter(), 5);  // the sixth frame carried counter 5
  EXPECT_EQ(decoder.decode(encoder.encode({CommandKind::set_flux, 0.5f})).result,
            CommandResult::accepted);
}

// The DBC states the protocol's widest ranges; a configuration beyond them is capped, so that
// no drive accepts a reference the DBC calls out of range.
TEST(DecoderLimits, AreCappedAtTheProtocolsRanges) {
  CommandDecoder decoder{1, CommandLimits{5000.0f, 0.01f, 10.0f}};
  CommandEncoder encoder{1};
  const float speed = protocol::kMaxSpeedReference_rad_s;
  const float flux2 = protocol::kMaxFlux2Reference_Wb2;
  EXPECT_EQ(decoder.decode(encoder.encode({CommandKind::set_speed, -speed})).result,
            CommandResult::accepted);
  EXPECT_EQ(decoder.decode(encoder.encode({CommandKind::set_speed, speed + 1.0f})).result,
            CommandResult::out_of_range);
  EXPECT_EQ(decoder.decode(encoder.encode({CommandKind::set_flux, flux2})).result,
            CommandResult::accepted);
  EXPECT_EQ(decoder.decode(encoder.encode({CommandKind::set_flux, flux2 + 0.5f})).result,
            CommandResult::out_of_range);
  // The table's ranges are these constants: what the DBC's [min|max] shows.
  const protocol::Signal& speed_signal = protocol::kSetSpeedSignals[2];
  EXPECT_TRUE(speed_signal.has_range);
  EXPECT_EQ(speed_signal.range_min, -speed);
  EXPECT_EQ(speed_signal.range_max, speed);
  EXPECT_EQ(protocol::kSetFluxSignals[2].range_max, flux2);
}

TEST_F(Decoder, EmergencyStopIgnoresTheCounter) {
  EXPECT_EQ(decoder.decode(encoder.encode({CommandKind::enable})).result, CommandResult::accepted);
  encoder.set_next_counter(9);  // out of step: every other command is refused...
  EXPECT_EQ(decoder.decode(encoder.encode({CommandKind::disable})).result,
            CommandResult::stale_counter);
  encoder.set_next_counter(9);  // ...but a stop is obeyed, even repeated
  EXPECT_EQ(decoder.decode(encoder.encode({CommandKind::emergency_stop})).result,
            CommandResult::accepted);
  encoder.set_next_counter(9);
  EXPECT_EQ(decoder.decode(encoder.encode({CommandKind::emergency_stop})).result,
            CommandResult::accepted);
  hal::CanFrame corrupt = encoder.encode({CommandKind::emergency_stop});
  corrupt.data[0] ^= 0x01;  // but never with a bad CRC
  EXPECT_EQ(decoder.decode(corrupt).result, CommandResult::bad_crc);
}

TEST_F(Decoder, RejectsReservedBitsAndUnknownMessages) {
  hal::CanFrame f = encoder.encode({CommandKind::enable});
  f.data[1] |= 0x40;
  f.data[0] = e2e_crc(f.id, f.data, f.length);  // a well-formed frame from a newer host
  EXPECT_EQ(decoder.decode(f).result, CommandResult::out_of_range);
  hal::CanFrame unknown;
  unknown.id = can_id(1, MessageId(0x1F));
  unknown.length = 2;
  EXPECT_EQ(decoder.decode(unknown).result, CommandResult::unknown_message);
}

TEST_F(Decoder, IgnoresOtherNodesAndTelemetry) {
  CommandEncoder other(2);
  const Decoded d = decoder.decode(other.encode({CommandKind::enable}));
  EXPECT_FALSE(d.for_this_node);
  const Decoded t = decoder.decode(encode_frame(1, MessageId::heartbeat, {3.0f}));
  EXPECT_FALSE(t.for_this_node);
  EXPECT_EQ(decoder.rejected_total(), 0u);
}

}  // namespace
}  // namespace imd::firmware::protocol
