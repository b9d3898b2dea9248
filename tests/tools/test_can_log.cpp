// The candump -L log format: the writer's exact text, writer/parser round trips, every frame
// kind candump writes (tests/tools/test_can_log_kinds.cpp), one specific error per kind of
// malformed line, and the file reader's PATH:LINE messages.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <fstream>
#include <iterator>
#include <optional>
#include <ostream>
#include <string>
#include <utility>

#include "tools/can_log/candump_log.hpp"

namespace imd::can_log {
namespace {

hal::CanFrame frame(uint16_t id, std::initializer_list<uint8_t> bytes) {
  hal::CanFrame f;
  f.id = id;
  for (const uint8_t b : bytes) f.data[f.length++] = b;
  return f;
}

TEST(can_log_writer, WritesWhatCandumpWrites) {
  EXPECT_EQ(format_log_line(0.0001, "can0", frame(0x022, {1, 3, 0, 0, 0, 0, 0, 0})),
            "(0.000100) can0 022#0103000000000000");
  EXPECT_EQ(format_log_line(12.5, "vcan0", frame(0x7FF, {0xAB, 0xCD})),
            "(12.500000) vcan0 7FF#ABCD");
  EXPECT_EQ(format_log_line(1.0, "can0", frame(0x022, {})), "(1.000000) can0 022#");
}

TEST(can_log_writer, ClampsWhatAFrameCannotCarry) {
  EXPECT_EQ(format_log_line(-1.0, "can0", frame(0x001, {})), "(0.000000) can0 001#");
  EXPECT_EQ(format_log_line(std::nan(""), "can0", frame(0x001, {})), "(0.000000) can0 001#");
  hal::CanFrame f = frame(0x801, {1});
  f.length = 12;
  EXPECT_EQ(format_log_line(0.0, "can0", f), "(0.000000) can0 001#0100000000000000");
}

TEST(can_log_parser, RoundTripsEveryLengthAndTime) {
  const double times_s[] = {0.0, 0.000001, 0.0001, 12.345678, 1'700'000'000.123456};
  for (const double t : times_s) {
    for (uint8_t length = 0; length <= 8; ++length) {
      hal::CanFrame f;
      f.id = static_cast<uint16_t>((length * 0x123 + 7) & 0x7FF);
      f.length = length;
      for (uint8_t i = 0; i < length; ++i) f.data[i] = static_cast<uint8_t>(0x11 * i + 0x0F);
      const std::string text = format_log_line(t, "can0", f);
      const ParseResult r = parse_log_line(text);
      ASSERT_TRUE(r.ok()) << text << ": " << r.error.message;
      EXPECT_EQ(r.line->time_us, std::llround(t * 1e6)) << text;
      EXPECT_NEAR(r.line->time_s, t, 1e-6) << text;
      EXPECT_EQ(r.line->iface, "can0");
      EXPECT_EQ(r.line->direction, Direction::unmarked);
      const std::optional<hal::CanFrame> back = classic_frame(r.line->frame);
      ASSERT_TRUE(back.has_value()) << text;
      EXPECT_EQ(back->id, f.id);
      EXPECT_EQ(back->length, f.length);
      EXPECT_EQ(back->data, f.data) << text;
      EXPECT_EQ(format_log_line(r.line->time_s, r.line->iface, r.line->frame), text);
    }
  }
}

TEST(can_log_parser, ReadsNanosecondTimestampsRoundedToTheMicrosecond) {
  // candump -N writes 9 digits; time_us rounds them half up, carrying into the seconds.
  const std::pair<const char*, int64_t> cases[] = {
      {"(1700000000.000250000) can0 022#01", 1'700'000'000'000'250},
      {"(0.000000499) can0 022#01", 0},
      {"(0.000000500) can0 022#01", 1},
      {"(12.345678901) can0 022#01", 12'345'679},
      {"(0.999999500) can0 022#01", 1'000'000},
      {"(999999999999.999999999) can0 022#01", 1'000'000'000'000'000'000},
  };
  for (const auto& [text, time_us] : cases) {
    const ParseResult r = parse_log_line(text);
    ASSERT_TRUE(r.ok()) << text << ": " << r.error.message;
    EXPECT_EQ(r.line->time_us, time_us) << text;
    EXPECT_EQ(r.line->frame.id, 0x022) << text;
  }
}

TEST(can_log_parser, AcceptsLowerCaseHexAndRemoteFrames) {
  const ParseResult lower = parse_log_line("(1.000000) can0 7ff#abcdef");
  ASSERT_TRUE(lower.ok()) << lower.error.message;
  EXPECT_EQ(lower.line->frame.id, 0x7FF);
  EXPECT_EQ(lower.line->frame.data[2], 0xEF);
  const ParseResult remote = parse_log_line("(1.000000) can0 022#R");
  ASSERT_TRUE(remote.ok()) << remote.error.message;
  EXPECT_EQ(remote.line->frame.type, FrameType::remote);
  EXPECT_EQ(remote.line->frame.length, 0);
  EXPECT_FALSE(classic_frame(remote.line->frame).has_value());
  const ParseResult remote3 = parse_log_line("(1.000000) can0 022#R3");
  ASSERT_TRUE(remote3.ok()) << remote3.error.message;
  EXPECT_EQ(remote3.line->frame.length, 3);
}

struct Malformed {
  const char* line;
  ParseErrorKind kind;
  const char* message;  ///< a part of the expected message
};

void PrintTo(const Malformed& m, std::ostream* os) {
  *os << quote(m.line);
}

/// The test name of a case: its kind and its index.
std::string case_name(const ::testing::TestParamInfo<Malformed>& info) {
  static constexpr const char* kKinds[] = {
      "empty_line",   "bad_timestamp",  "bad_separator",    "missing_field",   "bad_interface",
      "missing_hash", "bad_identifier", "identifier_range", "bad_error_frame", "bad_fd_flags",
      "fd_length",    "bad_data",       "odd_data",         "data_too_long",   "bad_remote",
      "bad_raw_dlc",  "trailing_text"};
  static_assert(std::size(kKinds) == std::size_t(ParseErrorKind::trailing_text) + 1);
  return std::string(kKinds[int(info.param.kind)]) + "_" + std::to_string(info.index);
}

class can_log_malformed : public ::testing::TestWithParam<Malformed> {};

TEST_P(can_log_malformed, GivesASpecificError) {
  const Malformed& m = GetParam();
  const ParseResult r = parse_log_line(m.line);
  ASSERT_FALSE(r.ok()) << m.line;
  EXPECT_EQ(r.error.kind, m.kind) << m.line << ": " << r.error.message;
  EXPECT_NE(r.error.message.find(m.message), std::string::npos)
      << "line: " << m.line << "\nmessage: " << r.error.message << "\nexpected: " << m.message;
}

using K = ParseErrorKind;
INSTANTIATE_TEST_SUITE_P(
    AllKinds, can_log_malformed,
    ::testing::Values(
        Malformed{"", K::empty_line, "empty line"},
        Malformed{"0.000100 can0 022#01", K::bad_timestamp, "bad timestamp '0.000100'"},
        Malformed{"(0.000100 can0 022#01", K::bad_timestamp, "expected '(SECONDS.MICROS)'"},
        Malformed{"(0.0001) can0 022#01", K::bad_timestamp, "'(0.0001)': expected"},
        Malformed{"(1) can0 022#01", K::bad_timestamp, "with 6 or 9 decimals"},
        Malformed{"(0.0001000) can0 022#01", K::bad_timestamp, "with 6 or 9 decimals"},
        Malformed{"(0.0000001000) can0 022#01", K::bad_timestamp, "'(0.0000001000)'"},
        Malformed{"(-1.000000) can0 022#01", K::bad_timestamp, "'(-1.000000)'"},
        Malformed{"(.000100) can0 022#01", K::bad_timestamp, "'(.000100)'"},
        Malformed{"(1234567890123.000000) can0 022#01", K::bad_timestamp, "6 or 9 decimals"},
        Malformed{"(0.000100)can0 022#01", K::bad_separator, "one space after the timestamp"},
        Malformed{"(0.000100)            vcan0 022#01", K::bad_separator,
                  "12 spaces before interface 'vcan0': candump pads names to at most 15"},
        Malformed{"(0.000100)\tcan0 022#01", K::bad_separator, "'\\x09c'"},
        Malformed{"(0.000100) can0  022#01", K::bad_separator, "after interface 'can0'"},
        Malformed{"(0.000100)", K::missing_field, "missing interface and frame"},
        Malformed{"(0.000100) ", K::missing_field, "missing interface and frame"},
        Malformed{"(0.000100) can0", K::missing_field, "missing frame after interface 'can0'"},
        Malformed{"(0.000100) can0 ", K::missing_field, "missing frame after interface"},
        Malformed{"(0.000100) ca\x01n 022#01", K::bad_interface, "'ca\\x01n'"},
        Malformed{"(0.000100) averyverylongname0 022#01", K::bad_interface, "longer than 15"},
        Malformed{"(0.000100) can0 02201", K::missing_hash, "bad frame '02201'"},
        Malformed{"(0.000100) can0 0G2#01", K::bad_identifier, "bad identifier '0G2'"},
        Malformed{"(0.000100) can0 22#01", K::bad_identifier, "expected 3 hex digits"},
        Malformed{"(0.000100) can0 #01", K::bad_identifier, "bad identifier ''"},
        Malformed{"(0.000100) can0 00022#01", K::bad_identifier, "bad identifier '00022'"},
        Malformed{"(0.000100) can0 800#01", K::identifier_range, "above 7FF"},
        Malformed{"(0.000100) can0 FFFFFFFF#01", K::identifier_range, "above 1FFFFFFF"},
        Malformed{"(0.000100) can0 40000000#01", K::identifier_range, "above 3FFFFFFF"},
        Malformed{"(0.000100) can0 18FF000G#01", K::bad_identifier, "bad identifier '18FF000G'"},
        Malformed{"(0.000100) can0 018FF0001#01", K::bad_identifier, "or 8 for an extended"},
        Malformed{"(0.000100) can0 18FF0001#001122334455667788", K::data_too_long,
                  "9 bytes: classic CAN carries at most 8"},
        Malformed{"(0.000100) can0 18FF0001#012", K::odd_data, "odd number of hex digits (3)"},
        Malformed{"(0.000100) can0 20000004##10004", K::bad_error_frame,
                  "error frame '20000004##10004' written as CAN FD"},
        Malformed{"(0.000100) can0 20000004#R", K::bad_error_frame, "written as remote ('R')"},
        Malformed{"(0.000100) can0 20000004#000400000000000000", K::data_too_long, "9 bytes"},
        Malformed{"(0.000100) can0 20000004#00X4", K::bad_data, "'X' is not a hex digit"},
        Malformed{"(0.000100) can0 022##", K::bad_fd_flags, "one hex digit of flags after '##'"},
        Malformed{"(0.000100) can0 022##G01", K::bad_fd_flags, "'##G01'"},
        Malformed{"(0.000100) can0 022###101", K::bad_fd_flags, "'###101'"},
        Malformed{"(0.000100) can0 022##1001122334455667788", K::fd_length,
                  "has 9 bytes: a CAN FD frame carries 0..8, 12, 16, 20, 24, 32, 48 or 64"},
        Malformed{"(0.000100) can0 18DA00F1##5000102030405060708090A0B0C0D0E0F1011121314",
                  K::fd_length, "has 21 bytes"},
        Malformed{"(0.000100) can0 18DA00F1##5000102030405060708090A0B0C0D0E0F101112"
                  "131415161718191A1B1C1D1E1F202122232425262728292A2B2C2D2E2F30313233343536"
                  "3738393A3B3C3D3E3F40",
                  K::data_too_long, "65 bytes: CAN FD carries at most 64"},
        Malformed{"(0.000100) can0 022##1012", K::odd_data, "odd number of hex digits (3)"},
        Malformed{"(0.000100) can0 022##10X", K::bad_data, "'X' is not a hex digit"},
        Malformed{"(0.000100) can0 022##1AA_E", K::bad_data, "'_' is not a hex digit"},
        Malformed{"(0.000100) can0 022#01X2", K::bad_data, "'X' is not a hex digit"},
        Malformed{"(0.000100) can0 022#01.02", K::bad_data, "'.' is not a hex digit"},
        Malformed{"(0.000100) can0 022#1122_E", K::bad_raw_dlc,
                  "bad raw DLC '_E': expected '_' and one digit 9..F, after exactly 8 data bytes"},
        Malformed{"(0.000100) can0 022#1122334455667788_8", K::bad_raw_dlc, "'_8'"},
        Malformed{"(0.000100) can0 022#1122334455667788_", K::bad_raw_dlc, "'_'"},
        Malformed{"(0.000100) can0 022#1122334455667788_EE", K::bad_raw_dlc, "'_EE'"},
        Malformed{"(0.000100) can0 022#R3_E", K::bad_raw_dlc, "after exactly 8 data bytes"},
        Malformed{"(0.000100) can0 022#R8_G", K::bad_raw_dlc, "'_G'"},
        Malformed{"(0.000100) can0 022#012", K::odd_data, "odd number of hex digits (3)"},
        Malformed{"(0.000100) can0 022#001122334455667788", K::data_too_long, "9 bytes"},
        Malformed{"(0.000100) can0 022#R9", K::bad_remote, "bad remote frame 'R9'"},
        Malformed{"(0.000100) can0 022#R12", K::bad_remote, "one length digit 0..8"},
        Malformed{"(0.000100) can0 022#RR", K::bad_remote, "bad remote frame 'RR'"},
        Malformed{"(0.000100) can0 022#01 X", K::trailing_text,
                  "after the frame: ' X' (only ' T' or ' R' may follow"},
        Malformed{"(0.000100) can0 022#01 t", K::trailing_text, "' t'"},
        Malformed{"(0.000100) can0 022#01  T", K::trailing_text, "'  T'"},
        Malformed{"(0.000100) can0 022#01 T ", K::trailing_text, "' T '"},
        Malformed{"(0.000100) can0 022#01 TR", K::trailing_text, "' TR'"},
        Malformed{"(0.000100) can0 022#01 ", K::trailing_text, "after the frame: ' '"}),
    case_name);

TEST(can_log_parser, QuotesBinaryAndLongText) {
  EXPECT_EQ(quote(std::string("a\0b\xff", 4)), "'a\\x00b\\xFF'");
  EXPECT_EQ(quote(std::string(60, 'x')), "'" + std::string(48, 'x') + "...'");
  const ParseResult r = parse_log_line("(0.000100) can0 022#\xff\xfe");
  ASSERT_FALSE(r.ok());
  EXPECT_NE(r.error.message.find("'\\xFF' is not a hex digit"), std::string::npos)
      << r.error.message;
}

std::string write_file(const std::string& name, const std::string& text) {
  const std::string path = ::testing::TempDir() + name;
  std::ofstream(path, std::ios::binary) << text;
  return path;
}

TEST(can_log_reader, ReadsFramesSkipsBlankLinesAndCarriageReturns) {
  const std::string path = write_file(
      "can_log_good.log", "(0.000100) can0 022#0103000000000000\r\n\n(0.000200) can0 7FF#\n");
  LogReader reader(path);
  ASSERT_TRUE(reader.is_open());
  ParsedLine line;
  ASSERT_TRUE(reader.next(line)) << reader.error();
  EXPECT_EQ(line.frame.id, 0x022);
  EXPECT_EQ(line.frame.length, 8);
  ASSERT_TRUE(reader.next(line)) << reader.error();
  EXPECT_EQ(line.frame.id, 0x7FF);
  EXPECT_EQ(reader.line_number(), 3);
  EXPECT_FALSE(reader.next(line));
  EXPECT_EQ(reader.error(), "");
  std::remove(path.c_str());
}

TEST(can_log_reader, ReportsPathAndLineOfABadLine) {
  const std::string path = write_file(
      "can_log_bad.log", "(0.000100) can0 022#01\n\n(0.000200) can0 022#01\n(0.3) can0 022#\n");
  LogReader reader(path);
  ParsedLine line;
  EXPECT_TRUE(reader.next(line));
  EXPECT_TRUE(reader.next(line));
  EXPECT_FALSE(reader.next(line));
  EXPECT_EQ(reader.error(),
            path + ":4: bad timestamp '(0.3)': expected '(SECONDS.MICROS)' with 6 or 9 decimals");
  EXPECT_FALSE(reader.next(line));  // stays stopped
  std::remove(path.c_str());
}

TEST(can_log_reader, ReportsAMissingFile) {
  LogReader reader("/nonexistent/run.log");
  EXPECT_FALSE(reader.is_open());
  EXPECT_EQ(reader.error(), "/nonexistent/run.log: cannot open file");
  ParsedLine line;
  EXPECT_FALSE(reader.next(line));
}

TEST(can_log_writer, WritesAFileTheReaderReads) {
  const std::string path = ::testing::TempDir() + "can_log_written.log";
  {
    LogWriter writer(path, "sim0");
    ASSERT_TRUE(writer.is_open()) << writer.error();
    writer.write(0.0001, frame(0x022, {1, 2, 3}));
    writer.write(0.0002, frame(0x033, {}));
    EXPECT_TRUE(writer.good());
  }
  LogReader reader(path);
  ParsedLine line;
  ASSERT_TRUE(reader.next(line)) << reader.error();
  EXPECT_EQ(line.iface, "sim0");
  EXPECT_EQ(line.time_us, 100);
  EXPECT_EQ(line.frame.length, 3);
  ASSERT_TRUE(reader.next(line)) << reader.error();
  EXPECT_EQ(line.frame.id, 0x033);
  EXPECT_FALSE(reader.next(line));
  std::remove(path.c_str());
  EXPECT_FALSE(LogWriter("/nonexistent/dir/x.log", "can0").is_open());
}

}  // namespace
}  // namespace imd::can_log
