#pragma once
/// Decoding of the drive's frames with the protocol table, the drive's status as the frames
/// report it, and the assembly of fast-telemetry samples into CSV rows. No I/O: the CLI feeds
/// frames from a socket or a log, tests and the fuzzer feed them directly.
#include <array>
#include <cstdint>
#include <optional>
#include <string>

#include "firmware/protocol/messages.hpp"
#include "hal/can_bus.hpp"

namespace imd::monitor {

namespace protocol = imd::firmware::protocol;

/// The most signals any message has.
inline constexpr std::size_t kMaxSignals = [] {
  std::size_t most = 0;
  for (const protocol::Message& m : protocol::kMessages) {
    if (m.signals.size() > most) most = m.signals.size();
  }
  return most;
}();

/// One signal of a decoded frame.
struct SignalValue {
  const protocol::Signal* signal = nullptr;
  int64_t raw = 0;
  double value = 0.0;                ///< physical, in the signal's unit
  const char* value_name = nullptr;  ///< for enumerated signals, or nullptr
};

enum class FrameKind : uint8_t {
  decoded,          ///< a known message of the watched node with its exact length
  other_node,       ///< another node's frame (not decoded)
  unknown_message,  ///< the watched node's identifier, but no such message in the table
  wrong_length,     ///< a known message whose length is not the table's (not decoded)
};

struct DecodedFrame {
  FrameKind kind = FrameKind::other_node;
  uint8_t node_id = 0;
  uint8_t message_id = 0;
  const protocol::Message* message = nullptr;  ///< set unless unknown_message / other_node
  std::array<SignalValue, kMaxSignals> signals{};
  std::size_t signal_count = 0;
};

/// Decodes a frame of node `node_id` by the protocol table.
DecodedFrame decode_frame(const hal::CanFrame& frame, uint8_t node_id);

/// "name=value unit" pairs of a decoded frame, e.g. "heartbeat state=running ...", with the
/// fault bits as one list of names: "faults=overcurrent,encoder" or "faults=none".
std::string describe(const DecodedFrame& frame);

/// The set bits of a fault word (bit n = fault code n) as fault names, e.g.
/// "overcurrent,encoder"; "none".
std::string fault_bit_names(int64_t fault_bits);

/// A physical value with as many decimals as the signal's scale has (0.01 -> 2), so that the
/// text adds no rounding to the telemetry's own resolution.
std::string format_physical(const protocol::Signal& signal, double value);

/// The name of an enumerated raw value, or its number.
std::string enum_text(const protocol::Signal& signal, int64_t raw);

/// One fast-telemetry sample: the three frames of one tick.
struct TelemetryRow {
  double time_s = 0.0;  ///< when telemetry_voltage (sent last) arrived
  double speed_rad_s = 0.0;
  double speed_ref_rad_s = 0.0;
  double flux2_Wb2 = 0.0;
  double flux2_ref_Wb2 = 0.0;
  double iA_A = 0.0;
  double iB_A = 0.0;
  double load_Nm = 0.0;
  double v_bus_V = 0.0;
  double u_alpha_V = 0.0;
  double u_beta_V = 0.0;
  int sample = 0;
  double rr_scale = 0.0;    ///< tracked rotor resistance over the record's
  std::string state;        ///< from the latest heartbeat; empty before the first one
  std::string first_fault;  ///< likewise
};

/// The CSV header line (no newline).
std::string csv_header();
/// One CSV line (no newline).
std::string csv_row(const TelemetryRow& row);

struct HeartbeatStatus {
  uint64_t count = 0;  ///< heartbeats received
  double time_s = 0.0;
  int64_t state = 0;
  int64_t fault_bits = 0;  ///< bit n = fault code n, from the fault-bit signals
  int64_t first_fault = 0;
  int64_t counter = 0;
  int64_t command_counter = 0;
  int64_t controller = 0;
  bool can_bus_off = false;
  int64_t rejected_commands = 0;
  int64_t limited = 0;  ///< the limit that holds the drive back (0 none)
  int64_t transitions = 0;
  int64_t stop = 0;         ///< the latched fault's stop category (0 none)
  bool brake = false;       ///< the holding brake is engaged
  int64_t reset_cause = 0;  ///< why the board last started
};

/// The version frame: what the drive runs (sent at each start, then at 1 Hz).
struct VersionStatus {
  uint64_t count = 0;
  int64_t protocol_version = 0;
  int64_t major = 0, minor = 0, patch = 0;
  bool dirty = false;
  uint32_t git_hash = 0;
};

struct AckStatus {
  uint64_t count = 0;
  double time_s = 0.0;
  int64_t message_id = 0;
  int64_t counter = 0;
  int64_t result = 0;
  int64_t rejected_total = 0;
};

struct StateChangeStatus {
  uint64_t count = 0;
  int64_t from = 0;
  int64_t to = 0;
  int64_t reason = 0;
  int64_t transitions = 0;
  int64_t time_ms = 0;
};

struct FaultReportStatus {
  uint64_t count = 0;
  int64_t first_fault = 0;
  int64_t fault_bits = 0;
  int64_t first_fault_time_ms = 0;
  int64_t detail = 0;
};

struct TimingStatus {
  uint64_t count = 0;
  double exec_mean_us = 0.0;
  double exec_max_us = 0.0;
  int64_t overruns = 0;
  double budget_us = 0.0;
};

struct FrameCounts {
  uint64_t total = 0;
  uint64_t decoded = 0;
  uint64_t other_nodes = 0;
  /// other_nodes by node id: whose traffic shared the bus (a wrong --node shows here).
  std::array<uint64_t, protocol::kMaxNodeId + 1> other_node_frames{};
  uint64_t unknown = 0;
  uint64_t wrong_length = 0;
  uint64_t commands = 0;            ///< host-to-drive frames to the watched node (from any host)
  uint64_t rows = 0;                ///< telemetry samples assembled
  uint64_t incomplete_samples = 0;  ///< telemetry_voltage before any speed_flux or current
  uint64_t stale_samples = 0;  ///< rows built with a speed_flux or current of an earlier sample
};

/// Everything the drive's frames said so far.
struct DriveStatus {
  double last_time_s = 0.0;
  HeartbeatStatus heartbeat;
  VersionStatus version;
  AckStatus ack;
  StateChangeStatus state_change;
  FaultReportStatus fault_report;
  TimingStatus timing;
  FrameCounts frames;
  std::optional<TelemetryRow> last_row;
};

/// Follows one node's frames.
class DriveMonitor {
 public:
  explicit DriveMonitor(uint8_t node_id) noexcept : node_id_(node_id) {}

  /// Takes one frame received at `time_s`; returns the telemetry row it completes, if any.
  std::optional<TelemetryRow> feed(double time_s, const hal::CanFrame& frame);

  const DriveStatus& status() const noexcept { return status_; }
  uint8_t node_id() const noexcept { return node_id_; }

 private:
  std::optional<TelemetryRow> on_voltage(double time_s, const DecodedFrame& d);

  uint8_t node_id_;
  DriveStatus status_;
  std::optional<DecodedFrame> speed_flux_;
  std::optional<DecodedFrame> current_;
  bool speed_flux_fresh_ = false;  ///< received since the last telemetry_voltage
  bool current_fresh_ = false;
};

}  // namespace imd::monitor
