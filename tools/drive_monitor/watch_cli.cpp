#include "tools/drive_monitor/watch_cli.hpp"

#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cstring>
#include <fstream>
#include <iostream>
#include <optional>

#include "firmware/protocol/messages.hpp"
#include "tools/can_log/candump_log.hpp"
#include "tools/drive_monitor/capture_report.hpp"
#include "tools/drive_monitor/cli_io.hpp"
#include "tools/drive_monitor/monitor.hpp"
#include "tools/drive_monitor/status_table.hpp"

namespace imd::monitor::cli {
namespace {

constexpr auto kRefreshPeriod = std::chrono::milliseconds(200);

/// The CSV output, when asked for ("-": standard output).
class CsvOutput {
 public:
  bool open(const std::string& path, std::string& error) {
    if (path.empty()) return true;
    if (path != "-") {
      file_.open(path, std::ios::out | std::ios::trunc);
      if (!file_.is_open()) {
        error = path + ": cannot open file for writing";
        return false;
      }
    }
    stream_ = path == "-" ? &std::cout : &file_;
    *stream_ << csv_header() << '\n';
    return true;
  }
  void write(const std::optional<TelemetryRow>& row) {
    if (row && stream_ != nullptr) *stream_ << csv_row(*row) << '\n';
  }
  /// False if a write failed.
  bool good() { return stream_ == nullptr || static_cast<bool>(stream_->flush()); }

 private:
  std::ofstream file_;
  std::ostream* stream_ = nullptr;
};

/// Redraws the table in place: cursor home, each line cleared to its end, the rest erased.
void redraw(const std::string& table) {
  std::string out = "\x1b[H";
  for (std::size_t start = 0; start < table.size();) {
    const std::size_t end = table.find('\n', start);
    out += table.substr(start, end - start) + "\x1b[K\n";
    start = end == std::string::npos ? table.size() : end + 1;
  }
  std::cout << out << "\x1b[J" << std::flush;
}

/// The end of a watch: the summary line, then the warning and kExitNoAnswer when the node was
/// not heard.
int finish_watch(const DriveMonitor& monitor, const SkippedFrames& skipped,
                 const std::string& source, bool live) {
  std::cerr << "drive_monitor: " << summary_line(monitor.status(), skipped, monitor.node_id(), live)
            << '\n';
  const auto warning = silent_node_warning(monitor.status(), monitor.node_id(), source);
  return warning ? fail(*warning, kExitNoAnswer) : 0;
}

int watch_log(const WatchOptions& o) {
  can_log::LogReader reader(o.log);
  if (!reader.is_open()) return fail(reader.error());
  CsvOutput csv;
  std::string error;
  if (!csv.open(o.csv, error)) return fail(error);
  DriveMonitor monitor(static_cast<uint8_t>(o.node));
  SkippedFrames skipped;
  can_log::ParsedLine line;
  double first_s = -1.0;
  while (reader.next(line)) {
    if (first_s < 0.0) first_s = line.time_s;
    if (o.duration_s > 0.0 && line.time_s - first_s > o.duration_s) break;
    if (const auto frame = take_frame(line.frame, skipped)) {
      csv.write(monitor.feed(line.time_s, *frame));
    }
  }
  if (!reader.error().empty()) return fail(reader.error());
  skipped.capture_lost = reader.dropped_frames();
  if (!csv.good()) return fail(o.csv + ": write error", kExitOutputError);
  if (!o.no_table) std::cout << render_table(monitor.status(), monitor.node_id(), o.log);
  return finish_watch(monitor, skipped, o.log, false);
}

int watch_live(const WatchOptions& o) {
  std::string error;
  const auto bus = LiveBus::open(o.bus, error);
  if (!bus) return fail(error);
  CsvOutput csv;
  if (!csv.open(o.csv, error)) return fail(error);
  set_stop_on_signals();
  const bool live_table = o.table || (!o.no_table && ::isatty(STDOUT_FILENO) == 1);
  if (live_table) std::cout << "\x1b[2J";
  DriveMonitor monitor(static_cast<uint8_t>(o.node));
  const Clock::time_point start = Clock::now();
  const Clock::time_point end = o.duration_s > 0.0
                                    ? start + std::chrono::duration_cast<Clock::duration>(
                                                  std::chrono::duration<double>(o.duration_s))
                                    : Clock::time_point::max();
  Clock::time_point next_refresh = start;
  while (g_stop == 0 && Clock::now() < end) {
    wait_readable(*bus, std::min(end, next_refresh));
    hal::CanFrame frame;
    while (bus->try_receive(frame)) {
      const double t_s = std::chrono::duration<double>(Clock::now() - start).count();
      csv.write(monitor.feed(t_s, frame));
    }
    if (const auto lost = bus->lost()) return fail(*lost);
    if (Clock::now() >= next_refresh) {
      next_refresh = Clock::now() + kRefreshPeriod;
      const std::optional<BusInfo> info = bus->info();
      if (live_table) {
        redraw(render_table(monitor.status(), monitor.node_id(), bus->name(),
                            info ? &*info : nullptr));
      }
    }
  }
  const std::optional<BusInfo> info = bus->info();
  const std::string table =
      render_table(monitor.status(), monitor.node_id(), bus->name(), info ? &*info : nullptr);
  if (live_table) {
    redraw(table);
  } else if (!o.no_table) {
    std::cout << table;
  }
  if (!csv.good()) return fail(o.csv + ": write error", kExitOutputError);
  // The bus counts what it drops; a classic socket is never given CAN FD frames.
  SkippedFrames skipped;
  skipped.error = info ? info->error_frames : 0;
  skipped.unsupported = bus->unsupported_frames();
  return finish_watch(monitor, skipped, bus->name(), true);
}

}  // namespace

CLI::App* add_watch_command(CLI::App& app, WatchOptions& o) {
  CLI::App* watch = app.add_subcommand("watch", "Decode the drive's frames: status table, CSV");
  watch->footer(
      "Frames that are not the node's (error, 29-bit, CAN FD and remote frames, other nodes, "
      "unknown messages) are skipped, and counted in a summary line on standard error.\n"
      "Exit codes: 0 success, 1 writing the CSV failed during the watch (disk full), 2 bad "
      "input (command line, interface, a CSV that cannot be created, malformed log line), 4 no "
      "frame from the node (is --node right?).");
  CLI::Option* can = add_bus_options(*watch, o.bus);
  watch->add_option("--log", o.log, "candump -L log file instead of a live bus")
      ->excludes(can)
      ->excludes("--socketcand");
  watch->add_option("--node", o.node, "Node id of the drive")
      ->check(CLI::Range(0, firmware::protocol::kMaxNodeId))
      ->capture_default_str();
  watch->add_option("--csv", o.csv,
                    "Write one row per fast-telemetry sample to this file ('-': stdout)");
  auto* table = watch->add_flag("--table", o.table, "Refresh the table even if not a terminal");
  watch->add_flag("--no-table", o.no_table, "Print no table")->excludes(table);
  watch->add_option("--duration-s", o.duration_s, "Stop after this time (log time with --log)")
      ->check(kSeconds);
  return watch;
}

int run_watch(const WatchOptions& o) {
  if (!o.bus.given() && o.log.empty()) {
    return fail("watch: give --can IFACE, --socketcand HOST:PORT or --log FILE");
  }
  return o.log.empty() ? watch_live(o) : watch_log(o);
}

}  // namespace imd::monitor::cli
