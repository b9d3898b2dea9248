// The stop a set of latched faults calls for (firmware/protection/stop_category.hpp): STO
// whenever any fault needs it, DC braking over SS1, and only the faults that may choose obey
// the policy.
#include <gtest/gtest.h>

#include "firmware/protection/stop_category.hpp"

namespace imd::firmware {
namespace {

constexpr uint16_t bit(FaultCode c) { return uint16_t(1u << static_cast<int>(c)); }

TEST(StopCategory, EveryFaultButThreeIsSto) {
  const StopPolicy p;  // the defaults: SS1, STO, DC braking
  for (int code = 1; code < kFaultCodeCount; ++code) {
    const auto c = static_cast<FaultCode>(code);
    const StopCategory expected = c == FaultCode::command_timeout ? StopCategory::ss1
                                  : c == FaultCode::encoder       ? StopCategory::dc_brake
                                                                  : StopCategory::sto;
    EXPECT_EQ(stop_category(bit(c), p), expected) << fault_name(c);
  }
  EXPECT_EQ(stop_category(0, p), StopCategory::none);
}

TEST(StopCategory, TheWorstOfSeveralFaultsWins) {
  const StopPolicy p;
  EXPECT_EQ(stop_category(bit(FaultCode::command_timeout) | bit(FaultCode::encoder), p),
            StopCategory::dc_brake);
  EXPECT_EQ(stop_category(bit(FaultCode::encoder) | bit(FaultCode::phase_loss), p),
            StopCategory::sto);
  EXPECT_EQ(stop_category(bit(FaultCode::command_timeout) | bit(FaultCode::overcurrent), p),
            StopCategory::sto);
}

TEST(StopCategory, APolicyCannotGiveAFaultAStopItMayNotTake) {
  // The encoder may not ramp (no speed to ramp with) and the watchdog may not DC-brake: such a
  // policy falls back to STO.
  StopPolicy p;
  p.encoder = StopCategory::ss1;
  p.command_timeout = StopCategory::dc_brake;
  p.emergency_stop = StopCategory::ss1;
  EXPECT_EQ(stop_category(bit(FaultCode::encoder), p), StopCategory::sto);
  EXPECT_EQ(stop_category(bit(FaultCode::command_timeout), p), StopCategory::sto);
  EXPECT_EQ(stop_category(bit(FaultCode::emergency_stop), p), StopCategory::ss1);
}

}  // namespace
}  // namespace imd::firmware
