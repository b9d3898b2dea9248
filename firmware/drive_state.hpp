#pragma once
/// The drive's states and fault codes. Their numbers are the CAN protocol's (the static_asserts
/// tie them to the value tables of firmware/protocol/messages.hpp).
#include <cstdint>
#include <cstring>

#include "firmware/protocol/messages.hpp"

namespace imd::firmware {

enum class DriveState : uint8_t {
  calibrating,  ///< ADC offsets measured with the PWM off, once after power-up
  idle,         ///< PWM off, waiting for enable
  magnetizing,  ///< flux build-up to the reference (B_k is singular at zero flux)
  running,      ///< the selected controller runs
  stopping,     ///< a disable command: ramp to a stop, then PWM off
  fault,        ///< PWM off, latched until clear_faults
  /// PWM off, enable refused: no valid motor record yet, or the one just written is being
  /// applied (the model is rebuilt outside the tick)
  unconfigured,
  identifying,  ///< the commissioning drives the motor (at standstill, then turning if let)
};
inline constexpr int kDriveStateCount = 8;

enum class FaultCode : uint8_t {
  none = 0,
  adc_offset,  ///< offset out of range at start-up
  overcurrent,
  magnetizing_timeout,
  non_finite,        ///< NaN or Inf in the duty path
  singular_control,  ///< B_k singular while running
  bus_undervoltage,
  bus_overvoltage,
  overrun,  ///< the tick took longer than its budget
  overspeed,
  encoder,          ///< no counts where the motion model demands them, or an implausible jump
  adc_stuck,        ///< the phase-current codes stopped changing while the voltage moved
  phase_loss,       ///< a phase carries much less current than the model says it should
  command_timeout,  ///< no valid command frame within the watchdog timeout while enabled
  emergency_stop,   ///< the emergency-stop command
  enable_input,     ///< the hardware enable input went inactive while the PWM was on
};
inline constexpr int kFaultCodeCount = 16;

/// Why the state changed (the state_change frame's reason).
enum class TransitionReason : uint8_t {
  calibrated,
  enable,
  magnetized,
  disable,
  stopped,
  fault,
  clear_faults,
  shutdown,  ///< the program running the drive is ending (Linux host-in-the-loop)
  parameters_written,  ///< a parameter write is being applied
  configured,          ///< the motor model is built from a valid record
  identify,            ///< the commissioning starts
  identified,          ///< it ended with a new record, being applied
  identification_failed,  ///< it ended without one (the reason is in identify_progress)
};

namespace detail {
constexpr bool same(const char* a, const char* b) {
  while (*a != '\0' && *a == *b) ++a, ++b;
  return *a == *b;
}
}  // namespace detail

constexpr const char* state_name(DriveState s) noexcept {
  return protocol::kStateValues[static_cast<int>(s)].name;
}
/// Stable lower-case name of a fault code, for logs and summaries.
constexpr const char* fault_name(FaultCode code) noexcept {
  const int i = static_cast<int>(code);
  return i < kFaultCodeCount ? protocol::kFaultValues[i].name : "unknown";
}
constexpr const char* reason_name(TransitionReason r) noexcept {
  return protocol::kTransitionReasonValues[static_cast<int>(r)].name;
}

static_assert(std::size(protocol::kStateValues) == kDriveStateCount);
static_assert(std::size(protocol::kFaultValues) == kFaultCodeCount);
static_assert(detail::same(state_name(DriveState::stopping), "stopping"));
static_assert(detail::same(state_name(DriveState::fault), "fault"));
static_assert(detail::same(fault_name(FaultCode::overrun), "overrun"));
static_assert(detail::same(fault_name(FaultCode::emergency_stop), "emergency_stop"));
static_assert(detail::same(reason_name(TransitionReason::clear_faults), "clear_faults"));
static_assert(detail::same(state_name(DriveState::unconfigured), "unconfigured"));
static_assert(detail::same(reason_name(TransitionReason::configured), "configured"));

}  // namespace imd::firmware
