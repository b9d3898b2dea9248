#pragma once
/// How the drive stops on a fault, in the categories of IEC 60204-1 and IEC 61800-5-2
/// (docs/safety.md, "Stop categories"):
///   * sto: safe torque off, the PWM off in the detecting tick (stop category 0);
///   * ss1: safe stop 1, the speed ramped to standstill under control, then STO (category 1),
///     time-limited by the stop timeout;
///   * dc_brake: a direct current in the stator brakes the rotor without any position or speed
///     feedback, for a time derived from the motor, then STO.
/// A fault that leaves the inverter, the current measurement or the control untrustworthy
/// always takes STO; only the command watchdog, the emergency stop and the encoder fault may
/// choose. The holding brake engages at STO (firmware/drive.cpp). Tick context.
#include <cstdint>

#include "firmware/drive_state.hpp"

namespace imd::firmware {

enum class StopCategory : uint8_t { none, sto, ss1, dc_brake };

/// The choices a board may make; every other fault is STO.
struct StopPolicy {
  StopCategory command_timeout = StopCategory::ss1;  ///< sto or ss1
  StopCategory emergency_stop = StopCategory::sto;   ///< sto or ss1
  StopCategory encoder = StopCategory::dc_brake;     ///< sto or dc_brake (at speed)
};

constexpr const char* stop_name(StopCategory c) noexcept {
  return protocol::kStopValues[static_cast<int>(c)].name;
}

/// The category a set of faults (bit n = fault code n) calls for: STO if any fault needs it,
/// else DC braking if any does (speed control is gone), else SS1.
constexpr StopCategory stop_category(uint16_t fault_bits, const StopPolicy& policy) noexcept {
  StopCategory worst = StopCategory::none;
  for (int code = 1; code < kFaultCodeCount; ++code) {
    if ((fault_bits & (1u << code)) == 0) continue;
    StopCategory c = StopCategory::sto;
    switch (static_cast<FaultCode>(code)) {
      case FaultCode::command_timeout:
        c = policy.command_timeout == StopCategory::ss1 ? StopCategory::ss1 : StopCategory::sto;
        break;
      case FaultCode::emergency_stop:
        c = policy.emergency_stop == StopCategory::ss1 ? StopCategory::ss1 : StopCategory::sto;
        break;
      case FaultCode::encoder:
        c = policy.encoder == StopCategory::dc_brake ? StopCategory::dc_brake
                                                      : StopCategory::sto;
        break;
      default:
        break;
    }
    if (c == StopCategory::sto) return c;
    if (c == StopCategory::dc_brake || worst == StopCategory::none) worst = c;
  }
  return worst;
}

}  // namespace imd::firmware
