// The socketcand server's text, without sockets: messages cut out of a stream whatever the
// reads' boundaries, `< send ... >` checked (bad hex, wrong length, 29-bit ids), the frames it
// writes in socketcand's own format, and a session's modes and answers.
#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "hal/linux/socketcand_session.hpp"
#include "hal/linux/socketcand_text.hpp"

namespace imd::hal {
namespace {

std::vector<SocketcandPiece> read_all(SocketcandReader& reader) {
  std::vector<SocketcandPiece> pieces;
  while (auto piece = reader.next()) pieces.push_back(*piece);
  return pieces;
}

TEST(socketcand_reader, JoinsAMessageSplitOverReads) {
  SocketcandReader reader;
  const std::string stream = "< send 21 2 1 f1 >";
  std::vector<SocketcandPiece> pieces;
  for (const char c : stream) {  // one byte per read, the worst split
    reader.feed(std::string(1, c));
    for (auto& p : read_all(reader)) pieces.push_back(p);
  }
  ASSERT_EQ(pieces.size(), 1u);
  EXPECT_FALSE(pieces[0].error);
  EXPECT_EQ(pieces[0].text, "send 21 2 1 f1");
}

TEST(socketcand_reader, SplitsManyMessagesInOneRead) {
  SocketcandReader reader;
  reader.feed("< open can0 >< rawmode >\n  < send 21 0 ><ech");
  const auto pieces = read_all(reader);
  ASSERT_EQ(pieces.size(), 3u);
  EXPECT_EQ(pieces[0].text, "open can0");
  EXPECT_EQ(pieces[1].text, "rawmode");
  EXPECT_EQ(pieces[2].text, "send 21 0");
  reader.feed("o >");
  const auto rest = read_all(reader);
  ASSERT_EQ(rest.size(), 1u);
  EXPECT_EQ(rest[0].text, "echo");
}

TEST(socketcand_reader, ReportsTextOutsideMessagesAndGoesOn) {
  SocketcandReader reader;
  reader.feed("junk< echo >");
  const auto pieces = read_all(reader);
  ASSERT_EQ(pieces.size(), 2u);
  EXPECT_TRUE(pieces[0].error);
  EXPECT_EQ(pieces[0].text, "text outside a message: 'junk'");
  EXPECT_FALSE(pieces[1].error);
  EXPECT_EQ(pieces[1].text, "echo");
}

TEST(socketcand_reader, ReportsAnUnclosedMessageAtTheNextOpening) {
  SocketcandReader reader;
  reader.feed("< send 21 1 < echo >");
  const auto pieces = read_all(reader);
  ASSERT_EQ(pieces.size(), 2u);
  EXPECT_TRUE(pieces[0].error);
  EXPECT_EQ(pieces[0].text, "message not closed: '< send 21 1'");
  EXPECT_EQ(pieces[1].text, "echo");
}

TEST(socketcand_reader, BoundsAMessageThatNeverEnds) {
  SocketcandReader reader;
  reader.feed("< " + std::string(SocketcandReader::kMaxMessage_chars, 'x'));
  const auto pieces = read_all(reader);
  ASSERT_EQ(pieces.size(), 1u);
  EXPECT_TRUE(pieces[0].error);
  EXPECT_NE(pieces[0].text.find("message longer than 256 characters"), std::string::npos);
  reader.feed("xx >< echo >");  // its rest, then a good message
  const auto rest = read_all(reader);
  ASSERT_EQ(rest.size(), 2u);
  EXPECT_TRUE(rest[0].error);
  EXPECT_EQ(rest[1].text, "echo");
}

TEST(socketcand_parse, ReadsASendFrame) {
  const SocketcandCommand c = parse_socketcand("send 7FF 3 1 f1 AB");
  ASSERT_EQ(c.kind, SocketcandCommand::Kind::send) << c.error;
  EXPECT_EQ(c.frame.id, 0x7FF);
  EXPECT_EQ(c.frame.length, 3);
  EXPECT_EQ(c.frame.data[0], 0x01);
  EXPECT_EQ(c.frame.data[1], 0xF1);
  EXPECT_EQ(c.frame.data[2], 0xAB);
  EXPECT_EQ(c.frame.data[3], 0x00);
  const SocketcandCommand empty = parse_socketcand("send 21 0");
  ASSERT_EQ(empty.kind, SocketcandCommand::Kind::send);
  EXPECT_EQ(empty.frame.length, 0);
}

TEST(socketcand_parse, RefusesBadHex) {
  SocketcandCommand c = parse_socketcand("send 2G 1 5");
  EXPECT_EQ(c.kind, SocketcandCommand::Kind::bad);
  EXPECT_EQ(c.error, "send: identifier '2G' is not hex");
  c = parse_socketcand("send 21 2 5 zz");
  EXPECT_EQ(c.kind, SocketcandCommand::Kind::bad);
  EXPECT_EQ(c.error, "send 21: data byte 1 'zz' is not 1 or 2 hex digits");
  c = parse_socketcand("send 21 1 123");  // three digits are no byte
  EXPECT_EQ(c.kind, SocketcandCommand::Kind::bad);
}

TEST(socketcand_parse, RefusesAWrongLength) {
  SocketcandCommand c = parse_socketcand("send 21 2 1");
  EXPECT_EQ(c.kind, SocketcandCommand::Kind::bad);
  EXPECT_EQ(c.error, "send 21: length 2 but 1 data bytes");
  c = parse_socketcand("send 21 9 1 2 3 4 5 6 7 8 9");
  EXPECT_EQ(c.error, "send 21: length '9' is not 0..8");
  c = parse_socketcand("send 21");
  EXPECT_EQ(c.kind, SocketcandCommand::Kind::bad);
}

TEST(socketcand_parse, RefusesIdentifiersTheDriveCannotHave) {
  EXPECT_EQ(parse_socketcand("send 800 0").error, "send: identifier 800 above 7FF");
  EXPECT_EQ(parse_socketcand("send 1AAAAAAA 0").error,
            "send 1AAAAAAA: 29-bit identifier; the drive uses 11-bit identifiers only");
}

TEST(socketcand_parse, KnowsTheModesAndNamesWhatIsNotServed) {
  EXPECT_EQ(parse_socketcand("open vcan0").kind, SocketcandCommand::Kind::open);
  EXPECT_EQ(parse_socketcand("open vcan0").channel, "vcan0");
  EXPECT_EQ(parse_socketcand("open").kind, SocketcandCommand::Kind::bad);
  EXPECT_EQ(parse_socketcand("rawmode").kind, SocketcandCommand::Kind::rawmode);
  EXPECT_EQ(parse_socketcand("subscribe 0 0 123").kind, SocketcandCommand::Kind::unsupported);
  EXPECT_EQ(parse_socketcand("frobnicate").error, "unknown command 'frobnicate'");
}

TEST(socketcand_format, WritesFramesAsSocketcandDoes) {
  CanFrame f;
  f.id = 0x21;
  f.length = 4;
  f.data = {0x1A, 0x22, 0x03, 0x44};
  EXPECT_EQ(format_socketcand_frame(f, 23, 424242), "< frame 021 23.424242 1A220344 >");
  f.length = 0;
  EXPECT_EQ(format_socketcand_frame(f, 1, 5), "< frame 021 1.000005  >");
  EXPECT_EQ(format_socketcand_error("bad <x>"), "< error bad ?x? >");
}

TEST(socketcand_session, GreetsOpensRawAndPassesFramesOn) {
  SocketcandSession session;
  std::string replies;
  std::vector<CanFrame> frames;
  session.receive("< send 21 0 >", replies, frames);  // before open: refused
  EXPECT_EQ(replies, "< error no bus open: open one first, e.g. open can0 >");
  EXPECT_TRUE(frames.empty());
  replies.clear();
  session.receive("< open can0 >< raw", replies, frames);
  EXPECT_EQ(replies, "< ok >");
  EXPECT_FALSE(session.raw());
  session.receive("mode >< send 21 1 5 >< send 21 1 zz >< echo >", replies, frames);
  EXPECT_EQ(replies,
            "< ok >< ok >< error send 21: data byte 0 'zz' is not 1 or 2 hex digits >< echo >");
  EXPECT_TRUE(session.raw());
  ASSERT_EQ(frames.size(), 1u);
  EXPECT_EQ(frames[0].id, 0x21);
  EXPECT_EQ(frames[0].data[0], 0x05);
  EXPECT_EQ(session.errors(), 2u);
  ASSERT_EQ(session.new_errors().size(), 1u);
}

}  // namespace
}  // namespace imd::hal
