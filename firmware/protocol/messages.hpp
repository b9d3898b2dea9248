#pragma once
/// The drive's CAN protocol: every message with its identifier, length, direction, rate and
/// signals. This table is the single source of truth: the firmware packs and unpacks with it,
/// drive_monitor decodes with it, and dbc_gen writes docs/can/drive.dbc from it.
///
/// Classic CAN, 11-bit identifiers: can_id = node_id * 32 + message id (node_id 0..63), as
/// ODrive does. Lower identifiers win arbitration, so the emergency stop is message 1.
/// Commands (host -> drive) carry a CRC-8 in byte 0 and a 4-bit alive counter in byte 1
/// (firmware/protocol/e2e.hpp). docs/can/protocol.md explains the behaviour behind each message.
#include <array>
#include <cstddef>
#include <cstdint>
#include <span>

#include "firmware/protocol/can_signal.hpp"
#include "firmware/protocol/fault_bits.hpp"
#include "firmware/protocol/value_tables.hpp"

namespace imd::firmware::protocol {

/// The layout of this table: +1 whenever a message or signal changes on the wire. The drive
/// sends it in its version frame, and the DBC file's VERSION is it.
inline constexpr uint8_t kProtocolVersion = 2;

/// The bus's one bit rate: the firmware's CAN controllers, the DBC's Baudrate and the docs all
/// follow it (tests/dbc/check_bit_rate.py checks the docs).
inline constexpr uint32_t kNominalBitrate_bit_s = 1'000'000;
inline constexpr int kMaxNodeId = 63;

inline constexpr int kFastTelemetryMinHz = 10;
inline constexpr int kFastTelemetryMaxHz = 1000;
/// The widest set_speed the drive accepts whatever its overspeed threshold (the decoder caps
/// that threshold here): a 2-pole motor at 300 Hz turns at 1885 rad/s.
inline constexpr float kMaxSpeedReference_rad_s = 2000.0f;
/// The largest set_flux the drive accepts whatever its max_flux2_Wb2 (capped here): the
/// configuration's default, (2 Wb)^2, above the rated flux of the motors this drive is for.
inline constexpr float kMaxFlux2Reference_Wb2 = 4.0f;

enum class MessageId : uint8_t {
  emergency_stop = 0x01,
  heartbeat = 0x02,
  fault_report = 0x03,
  disable = 0x04,
  enable = 0x05,
  clear_faults = 0x06,
  set_speed = 0x07,
  set_flux = 0x08,
  select_controller = 0x09,
  set_telemetry_rate = 0x0A,
  command_ack = 0x0B,
  state_change = 0x0C,
  parameter_access = 0x0D,
  parameter_value = 0x0E,
  identify = 0x0F,
  telemetry_speed_flux = 0x10,
  telemetry_current = 0x11,
  telemetry_voltage = 0x12,
  timing = 0x13,
  stage_timing_1 = 0x14,
  stage_timing_2 = 0x15,
  identify_progress = 0x16,
  version = 0x17,
};

enum class Direction : uint8_t {
  drive_to_host,  ///< telemetry and reports
  host_to_drive,  ///< commands (E2E protected)
};

/// How often a message is sent.
enum class Timing : uint8_t {
  cyclic,        ///< every period_ms
  configurable,  ///< fast telemetry: period_ms is the default, set_telemetry_rate changes it
  on_event,      ///< on a state change, a fault, or a command
};

struct Message {
  MessageId id;
  const char* name;
  uint8_t length;  ///< DLC, exact: a command of another length is rejected
  Direction direction;
  Timing timing;
  uint16_t period_ms;  ///< cyclic and configurable messages
  [[no_unique_address]] DocText comment = "";
  std::span<const Signal> signals;

  constexpr bool e2e() const noexcept { return direction == Direction::host_to_drive; }
};

constexpr uint16_t can_id(uint8_t node_id, MessageId id) noexcept {
  return static_cast<uint16_t>(node_id * 32 + static_cast<uint8_t>(id));
}
constexpr uint8_t node_of(uint16_t can_id) noexcept {
  return static_cast<uint8_t>(can_id >> 5);
}
constexpr uint8_t message_of(uint16_t can_id) noexcept {
  return static_cast<uint8_t>(can_id & 0x1F);
}

// --- the E2E header every command starts with
inline constexpr Signal kE2eCrc{
    "crc", 0, 8, false, 1, 1, 0.0f, "", "CRC-8 SAE J1850 over the CAN id and bytes 1 to DLC-1"};
inline constexpr Signal kE2eCounter{
    "counter", 8, 4, false, 1, 1, 0.0f, "", "alive counter, +1 (mod 16) per command frame"};

/// command_ack.message names the message it answers: its value table is every message's id and
/// name, filled from kMessages below. Declared here, as command_ack's signals (inside kMessages)
/// refer to it; kMessageCount gives its size before kMessages exists.
inline constexpr std::size_t kMessageCount = 23;
struct MessageIdNames {
  static const std::array<ValueName, kMessageCount> values;
};

// The 16-bit fault word (bit n = fault code n) starts at this bit in both messages that carry it.
inline constexpr uint8_t kHeartbeatFaultWordBit = 8;
inline constexpr uint8_t kFaultReportFaultWordBit = 8;

// --- signals, one array per message. Signal order is the telemetry's field order; the fault
// bits (firmware/protocol/fault_bits.hpp) come last and are packed as one word.
inline constexpr Signal kHeartbeatOwnSignals[] = {
    {"state", 0, 4, false, 1, 1, 0.0f, "", "drive state", kStateValues},
    {"first_fault", 24, 8, false, 1, 1, 0.0f, "", "first latched fault", kFaultValues},
    {"counter", 32, 8, false, 1, 1, 0.0f, "", "heartbeat count, wraps"},
    {"command_counter", 40, 4, false, 1, 1, 0.0f, "", "alive counter of the last command that passed the E2E checks"},
    {"controller", 44, 2, false, 1, 1, 0.0f, "", "selected controller", kControllerValues},
    {"can_bus_off", 46, 1, false, 1, 1, 0.0f, "", "the CAN controller was bus-off"},
    {"rejected_commands", 48, 6, false, 1, 1, 0.0f, "",
     "rejected command frames, wraps at 64 (command_ack carries the 16-bit total)"},
    {"limited", 54, 2, false, 1, 1, 0.0f, "",
     "the limit that holds the running drive from its reference (firmware/limitation.hpp)",
     kLimitedValues},
    {"transitions", 56, 8, false, 1, 1, 0.0f, "", "state transitions, wraps"},
    {"stop", 4, 2, false, 1, 1, 0.0f, "",
     "the stop category of the latched fault (firmware/protection/stop_category.hpp)",
     kStopValues},
    {"brake", 47, 1, false, 1, 1, 0.0f, "", "engaged: a brake line is configured and not driven"},
    {"reset_cause", 6, 2, false, 1, 1, 0.0f, "", "why the board last started (hal/watchdog.hpp)",
     kResetCauseValues},
};
inline constexpr auto kHeartbeatSignals =
    join(kHeartbeatOwnSignals, fault_bit_signals(kHeartbeatFaultWordBit));
inline constexpr Signal kFaultReportOwnSignals[] = {
    {"first_fault", 0, 8, false, 1, 1, 0.0f, "", "first latched fault", kFaultValues},
    {"first_fault_time_ms", 24, 32, false, 1, 1, 0.0f, "ms", "drive time of the first fault"},
    {"detail", 56, 8, false, 1, 1, 0.0f, "",
     "phase (0..2) for adc_offset, overcurrent and phase loss; 3: the hardware over-current trip"},
};
inline constexpr auto kFaultReportSignals =
    join(kFaultReportOwnSignals, fault_bit_signals(kFaultReportFaultWordBit));

// Commands carry the physical range the drive accepts (the DBC's [min|max]); the rule behind
// each range is stated with it, and CommandDecoder enforces it.
inline constexpr Signal kEmptyCommandSignals[] = {kE2eCrc, kE2eCounter};
inline constexpr Signal kSetSpeedSignals[] = {
    kE2eCrc,
    kE2eCounter,
    // +-kMaxSpeedReference_rad_s: the widest overspeed threshold the decoder takes.
    with_range({"speed_ref_rad_s", 16, 32, true, 1, 1000, 0.0f, "rad/s",
                "mechanical speed reference, within +-the drive's overspeed threshold"},
               -kMaxSpeedReference_rad_s, kMaxSpeedReference_rad_s)};
inline constexpr Signal kSetFluxSignals[] = {
    kE2eCrc,
    kE2eCounter,
    // 0..kMaxFlux2Reference_Wb2: the largest max_flux2_Wb2 the decoder takes; the drive's own
    // floor (min_flux2_command_Wb2, above 0) is configured per drive.
    with_range({"flux2_ref_Wb2", 16, 32, false, 1, 1000000, 0.0f, "Wb^2",
                "squared flux reference: rotor flux (dsmc) or stator flux (iol)"},
               0.0f, kMaxFlux2Reference_Wb2)};
inline constexpr Signal kIdentifySignals[] = {
    kE2eCrc,
    kE2eCounter,
    // 0..1: the values kIdentifyRotateValues names, the only ones accepted.
    with_range({"rotate", 16, 8, false, 1, 1, 0.0f, "",
                "1: after the standstill steps, turn the motor to measure inertia and friction "
                "(the shaft must be free to turn); 0: standstill only, the mechanics are kept; "
                "others are rejected",
                kIdentifyRotateValues},
               0.0f, float(std::size(kIdentifyRotateValues) - 1))};
inline constexpr Signal kSelectControllerSignals[] = {
    kE2eCrc,
    kE2eCounter,
    // 0..2: the laws kControllerValues names, the only ones accepted.
    with_range({"controller", 16, 8, false, 1, 1, 0.0f, "", "controller, only while idle",
                kControllerValues},
               0.0f, float(std::size(kControllerValues) - 1))};
inline constexpr Signal kSetTelemetryRateSignals[] = {
    kE2eCrc,
    kE2eCounter,
    // kFastTelemetryMinHz..kFastTelemetryMaxHz, what Telemetry::set_rate_Hz takes.
    with_range({"rate_Hz", 16, 16, false, 1, 1, 0.0f, "Hz", "fast telemetry rate, 10..1000"},
               float(kFastTelemetryMinHz), float(kFastTelemetryMaxHz))};
inline constexpr Signal kCommandAckSignals[] = {
    {"message", 0, 8, false, 1, 1, 0.0f, "", "message id of the command",
     {MessageIdNames::values.data(), kMessageCount}},
    {"counter", 8, 4, false, 1, 1, 0.0f, "", "its alive counter"},
    {"result", 12, 4, false, 1, 1, 0.0f, "", "accepted or why it was rejected",
     kCommandResultValues},
    {"rejected_total", 16, 16, false, 1, 1, 0.0f, "", "rejected command frames since boot"},
};
inline constexpr Signal kStateChangeSignals[] = {
    {"from", 0, 8, false, 1, 1, 0.0f, "", "previous state", kStateValues},
    {"to", 8, 8, false, 1, 1, 0.0f, "", "new state", kStateValues},
    {"reason", 16, 8, false, 1, 1, 0.0f, "", "why", kTransitionReasonValues},
    {"transitions", 24, 8, false, 1, 1, 0.0f, "", "state transitions, wraps"},
    {"time_ms", 32, 32, false, 1, 1, 0.0f, "ms", "drive time of the transition"},
};
inline constexpr Signal kParameterAccessSignals[] = {
    kE2eCrc,
    kE2eCounter,
    // 0..2: the operations kParameterOpValues names; another is rejected as out of range.
    with_range({"op", 12, 4, false, 1, 1, 0.0f, "",
                "read, write (only while idle) or save the record", kParameterOpValues},
               0.0f, float(std::size(kParameterOpValues) - 1)),
    // 0..10: the fields kMotorFieldValues names; another is answered with unknown_field.
    with_range({"field", 16, 8, false, 1, 1, 0.0f, "", "the record's field (read, write)",
                kMotorFieldValues},
               0.0f, float(std::size(kMotorFieldValues) - 1)),
    {"value", 24, 32, false, 1, 1, 0.0f, "", "the new value in the field's unit (write)", {},
     true},
};
inline constexpr Signal kParameterValueSignals[] = {
    {"field", 0, 8, false, 1, 1, 0.0f, "", "the record's field", kMotorFieldValues},
    {"op", 8, 4, false, 1, 1, 0.0f, "", "the operation answered", kParameterOpValues},
    {"status", 12, 4, false, 1, 1, 0.0f, "", "ok, or why the operation was refused",
     kParameterStatusValues},
    {"value", 16, 32, false, 1, 1, 0.0f, "", "the field's value after the operation", {}, true},
    {"complete", 48, 1, false, 1, 1, 0.0f, "", "every field has a valid value: the drive runs on it"},
    {"saved", 49, 1, false, 1, 1, 0.0f, "", "the record in use is the one in storage"},
};
inline constexpr Signal kIdentifyProgressSignals[] = {
    {"step", 0, 8, false, 1, 1, 0.0f, "", "the commissioning step in progress, or its end",
     kIdentifyStepValues},
    {"fraction", 8, 8, false, 1, 200, 0.0f, "", "progress through the step, 0..1"},
    {"failure", 16, 8, false, 1, 1, 0.0f, "", "why it failed (step failed)",
     kIdentifyFailureValues},
    {"seconds", 24, 16, false, 1, 10, 0.0f, "s", "drive time since the run began"},
};
inline constexpr Signal kSpeedFluxSignals[] = {
    {"speed_rad_s", 0, 16, true, 1, 100, 0.0f, "rad/s", "estimated mechanical speed"},
    {"speed_ref_rad_s", 16, 16, true, 1, 100, 0.0f, "rad/s", "speed reference (after the ramp)"},
    {"flux2_Wb2", 32, 16, false, 1, 10000, 0.0f, "Wb^2", "estimated squared flux"},
    {"flux2_ref_Wb2", 48, 16, false, 1, 10000, 0.0f, "Wb^2", "squared flux reference"},
};
inline constexpr Signal kCurrentSignals[] = {
    {"iA_A", 0, 16, true, 1, 100, 0.0f, "A", "stator current, rotor frame, A axis"},
    {"iB_A", 16, 16, true, 1, 100, 0.0f, "A", "stator current, rotor frame, B axis"},
    {"load_Nm", 32, 16, true, 1, 100, 0.0f, "N.m", "estimated load torque"},
    {"v_bus_V", 48, 16, false, 1, 10, 0.0f, "V", "measured DC bus"},
};
inline constexpr Signal kVoltageSignals[] = {
    {"u_alpha_V", 0, 16, true, 1, 10, 0.0f, "V", "stator voltage command, alpha"},
    {"u_beta_V", 16, 16, true, 1, 10, 0.0f, "V", "stator voltage command, beta"},
    {"sample", 32, 8, false, 1, 1, 0.0f, "", "telemetry sample count, wraps"},
    {"rr_scale", 40, 16, false, 1, 10000, 0.0f, "",
     "rotor resistance the drive runs on over the motor record's (tracked)"},
};
inline constexpr Signal kTimingSignals[] = {
    {"exec_mean_us", 0, 16, false, 1, 100, 0.0f, "us", "mean tick execution time"},
    {"exec_max_us", 16, 16, false, 1, 100, 0.0f, "us", "longest tick"},
    {"overruns", 32, 16, false, 1, 1, 0.0f, "", "ticks over budget, saturates"},
    {"budget_us", 48, 16, false, 1, 100, 0.0f, "us", "tick budget (0: not checked)"},
};

// Each stage of one tick (firmware/stages/stage_clock.hpp), from the last tick whose stages
// were timed.
inline constexpr Signal kStageTiming1Signals[] = {
    {"sense_us", 0, 16, false, 1, 100, 0.0f, "us", "sense stage: ADC and encoder"},
    {"estimate_us", 16, 16, false, 1, 100, 0.0f, "us", "estimate stage: observers, prediction"},
    {"supervise_us", 32, 16, false, 1, 100, 0.0f, "us", "supervise stage: commands, states"},
    {"law_us", 48, 16, false, 1, 100, 0.0f, "us", "law stage: magnetizing or control law"},
};
inline constexpr Signal kStageTiming2Signals[] = {
    {"modulate_us", 0, 16, false, 1, 100, 0.0f, "us", "modulate stage: limits, SVPWM"},
    {"protect_us", 16, 16, false, 1, 100, 0.0f, "us", "protect stage: every trip decision"},
    {"actuate_us", 32, 16, false, 1, 100, 0.0f, "us", "actuate stage: PWM write, observers"},
    {"publish_us", 48, 16, false, 1, 100, 0.0f, "us", "publish stage of the tick before"},
};

// The patch number has 7 bits so that the dirty flag fits in the frame beside the 32-bit hash.
inline constexpr Signal kVersionSignals[] = {
    {"protocol_version", 0, 8, false, 1, 1, 0.0f, "",
     "kProtocolVersion: the layout of the message table the firmware was built with"},
    {"firmware_major", 8, 8, false, 1, 1, 0.0f, "", "firmware version, major"},
    {"firmware_minor", 16, 8, false, 1, 1, 0.0f, "", "firmware version, minor"},
    {"firmware_patch", 24, 7, false, 1, 1, 0.0f, "", "firmware version, patch"},
    {"dirty", 31, 1, false, 1, 1, 0.0f, "",
     "1: built from a tree with uncommitted changes to tracked files"},
    {"git_hash", 32, 32, false, 1, 1, 0.0f, "",
     "the first 32 bits of the git commit the firmware was built from (0: none)"},
};

inline constexpr Message kMessages[] = {
    {MessageId::emergency_stop, "emergency_stop", 2, Direction::host_to_drive, Timing::on_event, 0,
     "PWM off at once, latched as a fault", kEmptyCommandSignals},
    {MessageId::heartbeat, "heartbeat", 8, Direction::drive_to_host, Timing::cyclic, 100,
     "state, faults and counters at 10 Hz", kHeartbeatSignals},
    {MessageId::fault_report, "fault_report", 8, Direction::drive_to_host, Timing::on_event, 0,
     "sent when a fault latches", kFaultReportSignals},
    {MessageId::disable, "disable", 2, Direction::host_to_drive, Timing::on_event, 0,
     "ramp to a stop, then PWM off", kEmptyCommandSignals},
    {MessageId::enable, "enable", 2, Direction::host_to_drive, Timing::on_event, 0,
     "idle -> magnetizing -> running", kEmptyCommandSignals},
    {MessageId::clear_faults, "clear_faults", 2, Direction::host_to_drive, Timing::on_event, 0,
     "fault -> idle", kEmptyCommandSignals},
    {MessageId::set_speed, "set_speed", 6, Direction::host_to_drive, Timing::on_event, 0,
     "speed reference, within +-overspeed", kSetSpeedSignals},
    {MessageId::set_flux, "set_flux", 6, Direction::host_to_drive, Timing::on_event, 0,
     "squared flux reference, (0, max]", kSetFluxSignals},
    {MessageId::select_controller, "select_controller", 3, Direction::host_to_drive,
     Timing::on_event, 0, "the control law (dsmc, iol, ifoc), only while idle", kSelectControllerSignals},
    {MessageId::set_telemetry_rate, "set_telemetry_rate", 4, Direction::host_to_drive,
     Timing::on_event, 0, "fast telemetry rate", kSetTelemetryRateSignals},
    {MessageId::command_ack, "command_ack", 4, Direction::drive_to_host, Timing::on_event, 0,
     "the result of every command frame addressed to this node", kCommandAckSignals},
    {MessageId::state_change, "state_change", 8, Direction::drive_to_host, Timing::on_event, 0,
     "sent on every state transition", kStateChangeSignals},
    {MessageId::parameter_access, "parameter_access", 7, Direction::host_to_drive,
     Timing::on_event, 0, "read or write a motor parameter, or save the record",
     kParameterAccessSignals},
    {MessageId::parameter_value, "parameter_value", 7, Direction::drive_to_host, Timing::on_event,
     0, "the answer to every parameter_access: the value or why it was refused",
     kParameterValueSignals},
    {MessageId::identify, "identify", 3, Direction::host_to_drive, Timing::on_event, 0,
     "start the commissioning from the nameplate (idle or unconfigured); disable aborts it",
     kIdentifySignals},
    {MessageId::identify_progress, "identify_progress", 5, Direction::drive_to_host,
     Timing::cyclic, 100, "the commissioning's step and progress at 10 Hz while it runs, and "
     "its end", kIdentifyProgressSignals},
    {MessageId::telemetry_speed_flux, "telemetry_speed_flux", 8, Direction::drive_to_host,
     Timing::configurable, 10, "fast telemetry 1/3", kSpeedFluxSignals},
    {MessageId::telemetry_current, "telemetry_current", 8, Direction::drive_to_host,
     Timing::configurable, 10, "fast telemetry 2/3", kCurrentSignals},
    {MessageId::telemetry_voltage, "telemetry_voltage", 7, Direction::drive_to_host,
     Timing::configurable, 10, "fast telemetry 3/3, sent last", kVoltageSignals},
    {MessageId::timing, "timing", 8, Direction::drive_to_host, Timing::cyclic, 100,
     "tick execution time at 10 Hz", kTimingSignals},
    {MessageId::stage_timing_1, "stage_timing_1", 8, Direction::drive_to_host, Timing::cyclic,
     100, "execution time of the tick's first four stages at 10 Hz", kStageTiming1Signals},
    {MessageId::stage_timing_2, "stage_timing_2", 8, Direction::drive_to_host, Timing::cyclic,
     100, "execution time of the tick's last four stages at 10 Hz", kStageTiming2Signals},
    {MessageId::version, "version", 8, Direction::drive_to_host, Timing::cyclic, 1000,
     "protocol and firmware version: at start-up before any other frame, then at 1 Hz",
     kVersionSignals},
};
static_assert(std::size(kMessages) == kMessageCount, "kMessageCount counts kMessages");

/// Every message's id and name, by id.
inline constexpr std::array<ValueName, kMessageCount> MessageIdNames::values = [] {
  std::array<ValueName, kMessageCount> names{};
  for (std::size_t i = 0; i < kMessageCount; ++i) {
    ValueName next{static_cast<int32_t>(kMessages[i].id), kMessages[i].name};
    std::size_t j = i;
    for (; j > 0 && names[j - 1].raw > next.raw; --j) names[j] = names[j - 1];
    names[j] = next;
  }
  return names;
}();

/// Each id's place in kMessages (kMessageCount: none), so that an id finds its message by one
/// look-up: the tick encodes frames by id. Ids are below 32 (the CAN id's low five bits).
inline constexpr std::array<uint8_t, 32> kMessageIndex = [] {
  std::array<uint8_t, 32> index{};
  index.fill(uint8_t(kMessageCount));
  for (std::size_t i = 0; i < kMessageCount; ++i) index[uint8_t(kMessages[i].id)] = uint8_t(i);
  return index;
}();

/// The definition of a message id, or nullptr.
constexpr const Message* find_message(uint8_t message_id) noexcept {
  const bool known = message_id < kMessageIndex.size() && kMessageIndex[message_id] < kMessageCount;
  return known ? &kMessages[kMessageIndex[message_id]] : nullptr;
}
constexpr const Message& message(MessageId id) noexcept {
  return *find_message(uint8_t(id));
}

/// The index of a signal in its message, or -1.
constexpr int find_signal(const Message& m, const char* name) noexcept;

/// A signal of a message by name, for constants: a typo fails to compile (the index is out of
/// range in a constant expression).
constexpr const Signal& signal_of(MessageId id, const char* name) noexcept {
  const Message& m = message(id);
  return m.signals[static_cast<std::size_t>(find_signal(m, name))];
}

/// The index of a signal in its message, or -1.
constexpr int find_signal(const Message& m, const char* name) noexcept {
  for (std::size_t i = 0; i < m.signals.size(); ++i) {
    const char* a = m.signals[i].name;
    const char* b = name;
    while (*a != '\0' && *a == *b) ++a, ++b;
    if (*a == *b) return static_cast<int>(i);
  }
  return -1;
}

}  // namespace imd::firmware::protocol
