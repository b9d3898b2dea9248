#pragma once
/// The names of the protocol's enumerated values (DBC VAL_ tables), one table per enumeration.
/// The firmware's enums are kept in step with them by static_asserts where the enums live.
#include "firmware/protocol/can_signal.hpp"

namespace imd::firmware::protocol {


inline constexpr ValueName kStateValues[] = {
    {0, "calibrating"}, {1, "idle"},     {2, "magnetizing"},
    {3, "running"},     {4, "stopping"}, {5, "fault"},
    {6, "unconfigured"}, {7, "identifying"},
};
inline constexpr ValueName kFaultValues[] = {
    {0, "none"},
    {1, "adc_offset"},
    {2, "overcurrent"},
    {3, "magnetizing_timeout"},
    {4, "non_finite"},
    {5, "singular_control"},
    {6, "bus_undervoltage"},
    {7, "bus_overvoltage"},
    {8, "overrun"},
    {9, "overspeed"},
    {10, "encoder"},
    {11, "adc_stuck"},
    {12, "phase_loss"},
    {13, "command_timeout"},
    {14, "emergency_stop"},
    {15, "enable_input"},
};
inline constexpr ValueName kControllerValues[] = {{0, "dsmc"}, {1, "iol"}, {2, "ifoc"}};
inline constexpr ValueName kResetCauseValues[] = {
    {0, "power_on"}, {1, "watchdog"}, {2, "software"}, {3, "other"}};
inline constexpr ValueName kStopValues[] = {
    {0, "none"}, {1, "sto"}, {2, "ss1"}, {3, "dc_brake"}};
inline constexpr ValueName kLimitedValues[] = {
    {0, "none"}, {1, "voltage"}, {2, "current"}, {3, "torque"}};
inline constexpr ValueName kCommandResultValues[] = {
    {0, "accepted"},      {1, "wrong_length"}, {2, "bad_crc"},     {3, "repeated_counter"},
    {4, "stale_counter"}, {5, "out_of_range"}, {6, "not_allowed"}, {7, "unknown_message"},
    {8, "not_in_image"},
};
inline constexpr ValueName kTransitionReasonValues[] = {
    {0, "calibrated"}, {1, "enable"}, {2, "magnetized"},   {3, "disable"},
    {4, "stopped"},    {5, "fault"},  {6, "clear_faults"}, {7, "shutdown"},
    {8, "parameters_written"}, {9, "configured"}, {10, "identify"}, {11, "identified"},
    {12, "identification_failed"},
};
inline constexpr ValueName kMotorFieldValues[] = {
    {0, "Rs_Ohm"},          {1, "Ls_H"},            {2, "Lm_H"},
    {3, "Rr_Ohm"},          {4, "Lr_H"},            {5, "J_kgm2"},
    {6, "pole_pairs"},      {7, "friction_Nms"},    {8, "rated_voltage_V"},
    {9, "rated_current_A"}, {10, "rated_frequency_Hz"},
};
inline constexpr ValueName kParameterOpValues[] = {{0, "read"}, {1, "write"}, {2, "save"}};
inline constexpr ValueName kIdentifyStepValues[] = {
    {0, "low_level"}, {1, "high_level"}, {2, "transient_inductance"},
    {3, "ramp_down"}, {4, "done"},       {5, "failed"},
    {6, "none"},      {7, "flux_up"},    {8, "accelerate"},
    {9, "coast"},     {10, "brake"},     {11, "field_down"},
};
inline constexpr ValueName kIdentifyFailureValues[] = {
    {0, "none"},        {1, "not_settled"}, {2, "voltage_limit"}, {3, "implausible"},
    {4, "no_nameplate"}, {5, "aborted"},    {6, "invalid_record"},
    {7, "no_motion"},  // done: the rotor did not turn, the mechanics were kept
    {8, "wrong_direction"}, {9, "overspeed"}, {10, "not_at_rest"}, {11, "stalled"},
};
inline constexpr ValueName kParameterStatusValues[] = {
    {0, "ok"},         {1, "not_idle"},  {2, "unknown_field"}, {3, "not_finite"},
    {4, "not_positive"}, {5, "negative"}, {6, "not_whole"},     {7, "no_leakage"},
    {8, "not_set"},    {9, "store_failed"}, {10, "busy"},
};
inline constexpr ValueName kIdentifyRotateValues[] = {{0, "standstill"}, {1, "rotate"}};

}  // namespace imd::firmware::protocol
