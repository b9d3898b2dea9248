// SocketCanBus without a CAN bus: the struct can_frame conversions, the error-frame accounting
// and the error paths of open() (on a kernel without CAN: a clear message, no exception).
#include <gtest/gtest.h>
#include <linux/can/error.h>

#include <cstring>
#include <string>

#include "hal/linux/socketcan_bus.hpp"

namespace imd::hal {
namespace {

can_frame kernel_frame(canid_t id, uint8_t length) {
  can_frame f;
  std::memset(&f, 0, sizeof f);
  f.can_id = id;
  f.len = length;
  for (int i = 0; i < CAN_MAX_DLEN; ++i) f.data[i] = static_cast<uint8_t>(0xA0 + i);
  return f;
}

TEST(socketcan_frame, ConvertsAStandardDataFrame) {
  CanFrame out;
  ASSERT_TRUE(from_socketcan(kernel_frame(0x123, 3), out));
  EXPECT_EQ(out.id, 0x123);
  EXPECT_EQ(out.length, 3);
  EXPECT_EQ(out.data[2], 0xA2);
  EXPECT_EQ(out.data[3], 0);  // bytes past the length are zero
  can_frame back;
  ASSERT_TRUE(to_socketcan(out, back));
  EXPECT_EQ(back.can_id, 0x123u);
  EXPECT_EQ(back.len, 3);
  EXPECT_EQ(back.data[2], 0xA2);
  EXPECT_EQ(back.data[3], 0);
}

TEST(socketcan_frame, RejectsExtendedRemoteErrorAndOversizedFrames) {
  CanFrame out;
  out.id = 0x55;
  EXPECT_FALSE(from_socketcan(kernel_frame(CAN_EFF_FLAG | 0x123, 2), out));
  EXPECT_FALSE(from_socketcan(kernel_frame(CAN_RTR_FLAG | 0x123, 2), out));
  EXPECT_FALSE(from_socketcan(kernel_frame(CAN_ERR_FLAG | CAN_ERR_BUSOFF, 8), out));
  EXPECT_FALSE(from_socketcan(kernel_frame(0x123, 9), out));
  EXPECT_EQ(out.id, 0x55);  // unchanged
}

TEST(socketcan_frame, RefusesToSendWhatClassicCanCannotCarry) {
  can_frame out;
  CanFrame f;
  f.id = 0x800;
  EXPECT_FALSE(to_socketcan(f, out));
  f.id = 0x7FF;
  f.length = 9;
  EXPECT_FALSE(to_socketcan(f, out));
  f.length = 8;
  EXPECT_TRUE(to_socketcan(f, out));
}

TEST(socketcan_errors, CountsErrorFramesAndTracksBusOff) {
  CanErrorState state;
  account_error_frame(kernel_frame(0x123, 8), state);  // not an error frame
  EXPECT_EQ(state.error_frames, 0u);
  account_error_frame(kernel_frame(CAN_ERR_FLAG | CAN_ERR_ACK, 8), state);
  EXPECT_EQ(state.error_frames, 1u);
  EXPECT_FALSE(state.bus_off);
  account_error_frame(kernel_frame(CAN_ERR_FLAG | CAN_ERR_BUSOFF | CAN_ERR_CRTL, 8), state);
  EXPECT_TRUE(state.bus_off);
  EXPECT_EQ(state.bus_off_events, 1u);
  EXPECT_EQ(state.last_error_class, CAN_ERR_BUSOFF | CAN_ERR_CRTL);
  account_error_frame(kernel_frame(CAN_ERR_FLAG | CAN_ERR_PROT, 8), state);
  EXPECT_TRUE(state.bus_off);  // still off until the controller restarts
  account_error_frame(kernel_frame(CAN_ERR_FLAG | CAN_ERR_RESTARTED, 8), state);
  EXPECT_FALSE(state.bus_off);
  EXPECT_EQ(state.error_frames, 4u);
}

TEST(socketcan_errors, DescribesErrorClasses) {
  EXPECT_EQ(describe_error_class(0), "none");
  EXPECT_EQ(describe_error_class(CAN_ERR_BUSOFF), "bus-off");
  EXPECT_EQ(describe_error_class(CAN_ERR_ACK | CAN_ERR_BUSOFF), "no-ack, bus-off");
}

TEST(socketcan_open, RejectsBadInterfaceNames) {
  std::string error;
  EXPECT_EQ(SocketCanBus::open("", error), nullptr);
  EXPECT_EQ(error, "empty CAN interface name");
  EXPECT_EQ(SocketCanBus::open("interface_name_17", error), nullptr);
  EXPECT_EQ(error, "interface_name_17: interface name longer than 15 characters");
}

/// Without CAN in the kernel, socket(PF_CAN) fails; with it, vcan9 should not exist.
TEST(socketcan_open, ExplainsAMissingInterfaceOrMissingCanSupport) {
  std::string error;
  EXPECT_EQ(SocketCanBus::open("vcan9", error), nullptr);
  if (error.find("socket(PF_CAN)") != std::string::npos) {
    EXPECT_EQ(error.rfind("vcan9: socket(PF_CAN): ", 0), 0u) << error;
    EXPECT_NE(error.find("support in this kernel"), std::string::npos) << error;
  } else {
    EXPECT_EQ(error, "vcan9: no such CAN interface");
  }
}

TEST(socketcan_open, RefusesAnInterfaceThatIsNotCan) {
  std::string error;
  EXPECT_EQ(SocketCanBus::open("lo", error), nullptr);
  if (error.find("socket(PF_CAN)") == std::string::npos) {
    EXPECT_EQ(error, "lo: not a CAN interface");
  }
}

}  // namespace
}  // namespace imd::hal
