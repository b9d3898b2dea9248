// Every frame kind candump -L writes (can-utils lib.c, snprintf_canframe; candump.c for the
// direction flag, the padded interface names and the DROPCOUNT lines of candump -d): what the
// parser makes of each, and that the writer writes each back to the same text. The malformed
// frame lines: test_can_log.cpp.
#include <gtest/gtest.h>

#include <cstdio>
#include <fstream>
#include <optional>
#include <string>

#include "tools/can_log/candump_log.hpp"

namespace imd::can_log {
namespace {

ParsedLine parsed(const std::string& text) {
  const ParseResult r = parse_log_line(text);
  EXPECT_TRUE(r.ok()) << text << ": " << r.error.message;
  return r.ok() ? *r.line : ParsedLine{};
}

TEST(can_log_kinds, ExtendedIdentifiers) {
  const ParsedLine j1939 = parsed("(1700000000.000250) can0 18FEF100#FFFF3C00FFFFFFFF");
  EXPECT_EQ(j1939.frame.type, FrameType::data);
  EXPECT_TRUE(j1939.frame.extended);
  EXPECT_EQ(j1939.frame.id, 0x18FEF100u);
  EXPECT_EQ(j1939.frame.length, 8);
  EXPECT_EQ(j1939.frame.data[2], 0x3C);
  EXPECT_FALSE(classic_frame(j1939.frame).has_value());
  // 8 digits are a 29-bit identifier whatever its value: never the drive's 11-bit 0x022.
  const ParsedLine low = parsed("(0.000100) can0 00000022#0100000001000001");
  EXPECT_TRUE(low.frame.extended);
  EXPECT_EQ(low.frame.id, 0x22u);
  EXPECT_FALSE(classic_frame(low.frame).has_value());
  EXPECT_TRUE(parsed("(0.000100) can0 1FFFFFFF#").frame.extended);
}

TEST(can_log_kinds, ErrorFrames) {
  // CAN_ERR_CRTL (0x04) with CAN_ERR_CRTL_RX_WARNING (0x04) in data[1]: linux/can/error.h.
  const ParsedLine e = parsed("(0.000100) can0 20000004#0004000000000000 R");
  EXPECT_EQ(e.frame.type, FrameType::error);
  EXPECT_EQ(e.frame.id, 0x04u);  // the error class, without CAN_ERR_FLAG
  EXPECT_FALSE(e.frame.extended);
  EXPECT_EQ(e.frame.length, 8);
  EXPECT_EQ(e.frame.data[1], 0x04);
  EXPECT_EQ(e.direction, Direction::received);
  EXPECT_FALSE(classic_frame(e.frame).has_value());
  const ParsedLine widest = parsed("(0.000100) can0 3FFFFFFF#");
  EXPECT_EQ(widest.frame.type, FrameType::error);
  EXPECT_EQ(widest.frame.id, 0x1FFFFFFFu);
}

TEST(can_log_kinds, CanFdFrames) {
  const ParsedLine empty = parsed("(0.000100) can0 123##4");
  EXPECT_EQ(empty.frame.type, FrameType::fd);
  EXPECT_EQ(empty.frame.fd_flags, 4);  // CANFD_FDF
  EXPECT_EQ(empty.frame.length, 0);
  const ParsedLine twelve = parsed("(0.000100) can0 022##10100000001000001AABBCCDD");
  EXPECT_EQ(twelve.frame.type, FrameType::fd);
  EXPECT_EQ(twelve.frame.id, 0x022u);
  EXPECT_FALSE(twelve.frame.extended);
  EXPECT_EQ(twelve.frame.fd_flags, 1);  // CANFD_BRS
  EXPECT_EQ(twelve.frame.length, 12);
  EXPECT_EQ(twelve.frame.data[11], 0xDD);
  // The drive's identifier in an FD frame is still not the drive's frame.
  EXPECT_FALSE(classic_frame(twelve.frame).has_value());
  std::string sixty_four = "(0.000100) can0 18DA00F1##7";
  for (int i = 0; i < 64; ++i) sixty_four += "A5";
  const ParsedLine big = parsed(sixty_four + " T");
  EXPECT_EQ(big.frame.type, FrameType::fd);
  EXPECT_TRUE(big.frame.extended);
  EXPECT_EQ(big.frame.length, 64);
  EXPECT_EQ(big.frame.data[63], 0xA5);
  EXPECT_EQ(big.direction, Direction::transmitted);
  for (const std::size_t n : {0u, 1u, 8u, 12u, 16u, 20u, 24u, 32u, 48u, 64u}) {
    EXPECT_TRUE(is_fd_length(n)) << n;
  }
  for (const std::size_t n : {9u, 10u, 11u, 13u, 33u, 63u, 65u}) EXPECT_FALSE(is_fd_length(n)) << n;
}

TEST(can_log_kinds, RemoteFramesAndRawDlc) {
  const ParsedLine extended_remote = parsed("(0.000100) can0 18FEF100#R");
  EXPECT_EQ(extended_remote.frame.type, FrameType::remote);
  EXPECT_TRUE(extended_remote.frame.extended);
  const ParsedLine raw_remote = parsed("(0.000100) can0 022#R8_E");
  EXPECT_EQ(raw_remote.frame.type, FrameType::remote);
  EXPECT_EQ(raw_remote.frame.length, 8);
  EXPECT_EQ(raw_remote.frame.raw_dlc, 0xE);
  const ParsedLine raw_data = parsed("(0.000100) can0 022#1122334455667788_9");
  EXPECT_EQ(raw_data.frame.type, FrameType::data);
  EXPECT_EQ(raw_data.frame.raw_dlc, 9);
  ASSERT_TRUE(classic_frame(raw_data.frame).has_value());  // 8 bytes on the wire all the same
  EXPECT_EQ(classic_frame(raw_data.frame)->length, 8);
}

TEST(can_log_kinds, DirectionFlags) {
  EXPECT_EQ(parsed("(0.000100) can0 022#01 T").direction, Direction::transmitted);
  EXPECT_EQ(parsed("(0.000100) can0 022#01 R").direction, Direction::received);
  EXPECT_EQ(parsed("(0.000100) can0 022#01").direction, Direction::unmarked);
  EXPECT_EQ(parsed("(0.000100) can0 022#R T").frame.type, FrameType::remote);
}

TEST(can_log_kinds, PaddedInterfaceNames) {
  // candump can0 vcan10 right-aligns "can0" to the width of "vcan10".
  const ParsedLine padded = parsed("(0.000100)   can0 022#01");
  EXPECT_EQ(padded.iface, "can0");
  EXPECT_EQ(parsed("(0.000100)           vcan0 022#01").iface, "vcan0");  // 10 + 5 = 15
}

TEST(can_log_kinds, TheWriterWritesEveryKindBackToTheSameText) {
  const char* lines[] = {
      "(0.000100) can0 022#0103000000000000",
      "(0.000100) can0 022#",
      "(1700000000.000250) can0 18FEF100#FFFF3C00FFFFFFFF R",
      "(0.000100) can0 00000022#01 T",
      "(0.000100) can0 20000004#0004000000000000 R",
      "(0.000100) can0 20000000#",
      "(0.000100) can0 123##4",
      "(0.000100) can0 022##10100000001000001AABBCCDD",
      "(0.000100) can0 18DA00F1##F00",
      "(0.000100) can0 022#R",
      "(0.000100) can0 022#R3 T",
      "(0.000100) can0 022#R8_E",
      "(0.000100) can0 18FEF100#R",
      "(0.000100) can0 022#1122334455667788_F",
  };
  for (const char* text : lines) {
    const ParsedLine line = parsed(text);
    EXPECT_EQ(format_log_line(line.time_s, line.iface, line.frame, line.direction), text);
  }
}

TEST(can_log_kinds, TheWriterRoundsAnFdLengthUpAndClipsTheRest) {
  LogFrame fd;
  fd.type = FrameType::fd;
  fd.id = 0x123;
  fd.length = 9;  // not an FD length: written as 12 bytes, the padding from data[]
  EXPECT_EQ(format_frame(fd), "123##0000000000000000000000000");
  LogFrame error;
  error.type = FrameType::error;
  error.id = 0xFFFFFFFF;  // only the error class bits are written
  EXPECT_EQ(format_frame(error), "3FFFFFFF#");
}

TEST(can_log_kinds, DropcountLines) {
  // candump -d: "DROPCOUNT: dropped %u CAN frame%s on '%s' socket (total drops %u)".
  EXPECT_EQ(
      parse_dropcount_line("DROPCOUNT: dropped 3 CAN frames on 'can0' socket (total drops 7)"), 3u);
  EXPECT_EQ(
      parse_dropcount_line("DROPCOUNT: dropped 1 CAN frame on 'vcan10' socket (total drops 1)"),
      1u);
  // Debian 12's can-utils (2020.11.0) writes candump's argument, filters included, and a
  // name longer than an interface's 15 characters is still the argument.
  EXPECT_EQ(parse_dropcount_line(
                "DROPCOUNT: dropped 2 CAN frames on 'can0,020:7E0,7FF:7FF' socket (total drops 2)"),
            2u);
  EXPECT_EQ(parse_dropcount_line(
                "DROPCOUNT: dropped 2 CAN frames on 'averyverylongname0' socket (total drops 9)"),
            2u);
  EXPECT_EQ(parse_dropcount_line("DROPCOUNT: dropped 4 CAN frames on 'any,#FFFFFFFF,j' socket "
                                 "(total drops 4)"),
            4u);
  const char* malformed[] = {
      "DROPCOUNT: dropped 1 CAN frames on 'can0' socket (total drops 1)",  // plural for 1
      "DROPCOUNT: dropped 2 CAN frame on 'can0' socket (total drops 2)",   // singular for 2
      "DROPCOUNT: dropped x CAN frames on 'can0' socket (total drops 2)",
      "DROPCOUNT: dropped 2 CAN frames on can0 socket (total drops 2)",
      "DROPCOUNT: dropped 2 CAN frames on '' socket (total drops 2)",
      "DROPCOUNT: dropped 2 CAN frames on 'can0' socket (total drops 2) ",
      "DROPCOUNT: dropped 2 CAN frames on 'can0' socket (total drops )",
      "DROPCOUNT: dropped 12345678901 CAN frames on 'can0' socket (total drops 2)",
      "DROPCOUNT: dropped 2 CAN frames on 'can0' socket (total drops 2)x",
      "DROPCOUNT: dropped 2 CAN frames on 'can0 socket (total drops 2)",
      "DROPCOUNT:",
  };
  for (const char* text : malformed) EXPECT_FALSE(parse_dropcount_line(text)) << text;
}

TEST(can_log_kinds, TheReaderCountsDropcountLinesAndStopsAtABadOne) {
  const std::string path = ::testing::TempDir() + "can_log_dropcount.log";
  std::ofstream(path) << "(0.000100) can0 022#01 R\n"
                         "DROPCOUNT: dropped 2 CAN frames on 'can0' socket (total drops 2)\n"
                         "(0.000200) can0 022#02 R\n"
                         "DROPCOUNT: dropped 1 CAN frame on 'can0' socket (total drops 3)\n"
                         "DROPCOUNT: dropped 5 frames\n";
  LogReader reader(path);
  ParsedLine line;
  ASSERT_TRUE(reader.next(line)) << reader.error();
  ASSERT_TRUE(reader.next(line)) << reader.error();
  EXPECT_EQ(line.frame.data[0], 0x02);
  EXPECT_EQ(reader.dropped_frames(), 2u);
  EXPECT_FALSE(reader.next(line));
  EXPECT_EQ(reader.dropped_frames(), 3u);
  EXPECT_EQ(reader.error(), path +
                                ":5: bad DROPCOUNT line 'DROPCOUNT: dropped 5 frames': expected "
                                "\"DROPCOUNT: dropped N CAN frames on 'IFACE' socket (total "
                                "drops M)\"");
  std::remove(path.c_str());
}

}  // namespace
}  // namespace imd::can_log
