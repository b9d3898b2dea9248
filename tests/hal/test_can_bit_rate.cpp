// The bit-rate check of a SocketCAN interface over rtnetlink, on the interfaces every Linux
// host has (no CAN controller is needed): the loopback is not CAN, a missing interface is
// named, and a virtual CAN interface passes whatever the rate when the host has one.
#include <gtest/gtest.h>
#include <net/if.h>

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

}  // namespace
}  // namespace imd::hal
