#pragma once
/// What a drive_hil run measured: the loop's timing (wake-up latency and execution time, as
/// histograms with their percentiles), the drive's end state and the CAN counters. Printed as
/// a short text summary, and written as JSON by --latency-report.
#include <nlohmann/json.hpp>

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "hal/linux/latency_histogram.hpp"
#include "hal/linux/queued_can_bus.hpp"
#include "hal/linux/socketcand_server.hpp"

namespace imd::firmware {

struct HilRunFacts {
  std::string scenario;
  std::string stop_reason;  ///< "duration", "SIGINT", "SIGTERM", "plant diverged"
  uint32_t period_ns = 0;
  double wall_s = 0.0;
  uint64_t ticks = 0;
  uint64_t missed_periods = 0;
  bool realtime = false;  ///< SCHED_FIFO granted
  int fifo_priority = 0;
  std::vector<std::string> warnings;
  const hal::LatencyHistogram* wakeup = nullptr;
  const hal::LatencyHistogram* execution = nullptr;
  std::string state, first_fault, precision;
  uint64_t drive_overruns = 0;
  uint32_t telemetry_dropped = 0;
  std::string can_iface;  ///< "none" without a bus, "socketcand:127.0.0.1:29536" over TCP
  std::optional<hal::QueuedCanCounters> can;
  std::optional<hal::SocketcandCounters> socketcand;  ///< with --can socketcand:...
};

/// Percentiles of a histogram in us: p50, p99, p99.9, max, mean, and the samples of at least
/// one period (wake-ups that came after the next deadline had begun).
nlohmann::json histogram_json(const hal::LatencyHistogram& h, uint32_t period_ns);

nlohmann::json report_json(const HilRunFacts& facts);

/// A few lines for the console.
std::string report_text(const HilRunFacts& facts);

}  // namespace imd::firmware
