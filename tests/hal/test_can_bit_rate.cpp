// The bit-rate check of a SocketCAN interface over rtnetlink. On the interfaces every Linux
// host has (no CAN controller is needed): the loopback is not CAN, a missing interface is
// named, and a virtual CAN interface passes whatever the rate when the host has one. On
// RTM_NEWLINK answers built here byte by byte: a CAN controller with and without a bit
// timing, a virtual one, a link without IFLA_LINKINFO, answers cut short, the kernel's error.
#include <gtest/gtest.h>
#include <linux/can/netlink.h>
#include <linux/if_link.h>
#include <linux/netlink.h>
#include <linux/rtnetlink.h>
#include <net/if.h>

#include <algorithm>
#include <cerrno>
#include <cstring>
#include <optional>
#include <string>
#include <vector>

#include "hal/linux/can_bit_rate.hpp"

namespace imd::hal {
namespace {

TEST(CanBitRate, TheLoopbackIsReadAndIsNotACanInterface) {
  std::string error;
  const std::optional<CanLinkInfo> info = can_link_info("lo", error);
  ASSERT_TRUE(info.has_value()) << error;
  EXPECT_EQ(info->kind, "");  // the loopback has no IFLA_LINKINFO kind
  EXPECT_EQ(info->bit_rate_bit_s, 0u);
  EXPECT_EQ(bit_rate_mismatch("lo", 1'000'000), "lo: not a CAN interface (link kind '')");
}

TEST(CanBitRate, AMissingInterfaceIsNamed) {
  std::string error;
  EXPECT_FALSE(can_link_info("nocan7", error).has_value());
  EXPECT_EQ(error, "nocan7: no such network interface");
  EXPECT_EQ(bit_rate_mismatch("nocan7", 1'000'000), "nocan7: no such network interface");
}

TEST(CanBitRate, AVirtualCanInterfaceHasNoBitRateToCheck) {
  if (if_nametoindex("vcan0") == 0) GTEST_SKIP() << "no vcan0 on this host";
  std::string error;
  const std::optional<CanLinkInfo> info = can_link_info("vcan0", error);
  ASSERT_TRUE(info.has_value()) << error;
  EXPECT_EQ(info->kind, "vcan");
  EXPECT_EQ(bit_rate_mismatch("vcan0", 1'000'000), "");
  EXPECT_EQ(bit_rate_mismatch("vcan0", 125'000), "");
}

/// Netlink bytes as the kernel lays them out: 4-byte aligned attributes, nested by length.
class Bytes {
 public:
  template <typename T>
  void put(const T& value) {
    const auto* p = reinterpret_cast<const std::byte*>(&value);
    bytes_.insert(bytes_.end(), p, p + sizeof value);
  }
  void pad() { bytes_.resize(RTA_ALIGN(bytes_.size())); }
  /// An attribute of `type` holding `payload`, padded.
  void attribute(uint16_t type, const std::vector<std::byte>& payload) {
    put(rtattr{static_cast<uint16_t>(RTA_LENGTH(payload.size())), type});
    bytes_.insert(bytes_.end(), payload.begin(), payload.end());
    pad();
  }
  void text(uint16_t type, const char* value) {
    const auto* p = reinterpret_cast<const std::byte*>(value);
    attribute(type, std::vector<std::byte>(p, p + std::strlen(value) + 1));
  }
  std::vector<std::byte>& data() { return bytes_; }

 private:
  std::vector<std::byte> bytes_;
};

/// An IFLA_LINKINFO payload: the kind and, for a bit rate, IFLA_INFO_DATA with a bit timing.
std::vector<std::byte> link_info(const char* kind, std::optional<uint32_t> bit_rate_bit_s) {
  Bytes info;
  info.text(IFLA_INFO_KIND, kind);
  if (bit_rate_bit_s) {
    can_bittiming timing{};
    timing.bitrate = *bit_rate_bit_s;
    timing.sample_point = 875;
    Bytes data;
    data.put(rtattr{static_cast<uint16_t>(RTA_LENGTH(sizeof timing)), IFLA_CAN_BITTIMING});
    data.put(timing);
    Bytes state;  // another IFLA_CAN_* attribute before it, to be skipped
    state.attribute(IFLA_CAN_STATE, std::vector<std::byte>(4));
    state.data().insert(state.data().end(), data.data().begin(), data.data().end());
    info.attribute(IFLA_INFO_DATA | NLA_F_NESTED, state.data());
  }
  return info.data();
}

/// An RTM_NEWLINK message: header, ifinfomsg, IFNAME, MTU and, when given, IFLA_LINKINFO.
std::vector<std::byte> new_link(const std::optional<std::vector<std::byte>>& info) {
  Bytes body;
  body.put(ifinfomsg{});
  body.text(IFLA_IFNAME, "can0");
  body.attribute(IFLA_MTU, std::vector<std::byte>(4));
  if (info) body.attribute(IFLA_LINKINFO | NLA_F_NESTED, *info);
  Bytes message;
  message.put(
      nlmsghdr{static_cast<uint32_t>(NLMSG_HDRLEN + body.data().size()), RTM_NEWLINK, 0, 1, 0});
  message.data().insert(message.data().end(), body.data().begin(), body.data().end());
  return message.data();
}

std::vector<std::byte> error_message(int errno_value) {
  Bytes message;
  message.put(
      nlmsghdr{static_cast<uint32_t>(NLMSG_LENGTH(sizeof(nlmsgerr))), NLMSG_ERROR, 0, 1, 0});
  nlmsgerr error{};
  error.error = -errno_value;
  message.put(error);
  return message.data();
}

CanLinkInfo parsed(const std::vector<std::byte>& answer) {
  std::string error;
  const std::optional<CanLinkInfo> info = parse_link_message(answer, error);
  EXPECT_TRUE(info.has_value()) << error;
  return info.value_or(CanLinkInfo{"(none)", 0});
}

std::string parse_error(const std::vector<std::byte>& answer) {
  std::string error;
  EXPECT_FALSE(parse_link_message(answer, error).has_value());
  return error;
}

TEST(CanBitRate, ACanControllerGivesItsBitTiming) {
  const CanLinkInfo info = parsed(new_link(link_info("can", 500'000)));
  EXPECT_EQ(info.kind, "can");
  EXPECT_EQ(info.bit_rate_bit_s, 500'000u);
  EXPECT_EQ(bit_rate_mismatch("can0", info, 500'000), "");
  EXPECT_EQ(bit_rate_mismatch("can0", info, 1'000'000),
            "can0: runs at 500000 bit/s, the protocol at 1000000 bit/s: ip link set can0 down; "
            "ip link set can0 type can bitrate 1000000; ip link set can0 up");
}

TEST(CanBitRate, ACanControllerWithoutABitRateIsToldHowToSetOne) {
  const CanLinkInfo bare = parsed(new_link(link_info("can", std::nullopt)));
  EXPECT_EQ(bare.kind, "can");
  EXPECT_EQ(bare.bit_rate_bit_s, 0u);
  const CanLinkInfo zero = parsed(new_link(link_info("can", 0)));
  EXPECT_EQ(zero.bit_rate_bit_s, 0u);
  for (const CanLinkInfo& info : {bare, zero}) {
    EXPECT_EQ(bit_rate_mismatch("can1", info, 1'000'000),
              "can1: no bit rate configured, the protocol runs at 1000000 bit/s: ip link set "
              "can1 down; ip link set can1 type can bitrate 1000000; ip link set can1 up");
  }
}

TEST(CanBitRate, VirtualLinksPassAndOthersAreNotCan) {
  const CanLinkInfo vcan = parsed(new_link(link_info("vcan", std::nullopt)));
  EXPECT_EQ(vcan.kind, "vcan");
  EXPECT_EQ(bit_rate_mismatch("vcan0", vcan, 1'000'000), "");
  EXPECT_EQ(
      bit_rate_mismatch("vxcan0", parsed(new_link(link_info("vxcan", std::nullopt))), 1'000'000),
      "");
  const CanLinkInfo none = parsed(new_link(std::nullopt));  // no IFLA_LINKINFO: a plain NIC
  EXPECT_EQ(none.kind, "");
  EXPECT_EQ(bit_rate_mismatch("eth0", none, 1'000'000), "eth0: not a CAN interface (link kind '')");
  EXPECT_EQ(bit_rate_mismatch("br0", parsed(new_link(link_info("bridge", std::nullopt))), 1),
            "br0: not a CAN interface (link kind 'bridge')");
}

TEST(CanBitRate, TheKernelsErrorIsReportedWithItsErrno) {
  EXPECT_EQ(parse_error(error_message(EPERM)),
            "the kernel answered: " + std::string(std::strerror(EPERM)) + " (errno 1)");
  EXPECT_EQ(parse_error(error_message(ENODEV)),
            "the kernel answered: " + std::string(std::strerror(ENODEV)) + " (errno 19)");
  EXPECT_EQ(parse_error(error_message(0)), "unexpected answer: an acknowledgement, no link");
}

TEST(CanBitRate, AnotherMessageTypeIsNamed) {
  std::vector<std::byte> answer = new_link(std::nullopt);
  nlmsghdr header{};
  std::memcpy(&header, answer.data(), sizeof header);
  header.nlmsg_type = NLMSG_DONE;
  std::memcpy(answer.data(), &header, sizeof header);
  EXPECT_EQ(parse_error(answer), "unexpected answer: message type 3, expected RTM_NEWLINK (16)");
}

TEST(CanBitRate, AnswersCutShortAreErrorsNotAnotherKind) {
  EXPECT_EQ(parse_error({}), "truncated answer: 0 bytes, no message header");
  std::vector<std::byte> answer = new_link(link_info("can", 1'000'000));
  // recv() gave fewer bytes than the header claims.
  EXPECT_EQ(parse_error(std::vector<std::byte>(answer.begin(), answer.end() - 4)),
            "truncated answer: " + std::to_string(answer.size() - 4) +
                " bytes, the message claims " + std::to_string(answer.size()));
  // The header agrees, but the last attribute (IFLA_LINKINFO) claims more than is left.
  answer.resize(answer.size() - 8);
  nlmsghdr header{};
  std::memcpy(&header, answer.data(), sizeof header);
  header.nlmsg_len = static_cast<uint32_t>(answer.size());
  std::memcpy(answer.data(), &header, sizeof header);
  const std::string error = parse_error(answer);
  EXPECT_NE(error.find("truncated answer: an attribute of RTM_NEWLINK at byte"), std::string::npos)
      << error;
  // An IFLA_CAN_BITTIMING shorter than struct can_bittiming.
  Bytes short_timing;
  short_timing.attribute(IFLA_CAN_BITTIMING, std::vector<std::byte>(8));
  Bytes info;
  info.text(IFLA_INFO_KIND, "can");
  info.attribute(IFLA_INFO_DATA, short_timing.data());
  EXPECT_EQ(parse_error(new_link(info.data())),
            "truncated answer: IFLA_CAN_BITTIMING of 8 bytes, expected 32");
}

TEST(CanBitRate, AnUnalignedAnswerIsReadAsWell) {
  const std::vector<std::byte> answer = new_link(link_info("can", 250'000));
  std::vector<std::byte> shifted(answer.size() + 1);
  std::copy(answer.begin(), answer.end(), shifted.begin() + 1);
  std::string error;
  const auto info = parse_link_message(std::span(shifted).subspan(1), error);
  ASSERT_TRUE(info.has_value()) << error;
  EXPECT_EQ(info->bit_rate_bit_s, 250'000u);
}

}  // namespace
}  // namespace imd::hal
