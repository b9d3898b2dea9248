#pragma once
/// drive_monitor watch: decodes one node's frames from a CAN interface, a socketcand server or a candump -L log into
/// the status table and a telemetry CSV; skips and counts everything else a shared bus carries
/// and ends with a summary line (capture_report.hpp). Exit codes: 0 success, kExitOutputError
/// writing the CSV failed during the watch (disk full), kExitBadInput bad input before anything
/// ran (command line, interface, a CSV that cannot be created) or a malformed log line,
/// kExitNoAnswer no frame at all from the node.
#include <CLI/CLI.hpp>

#include <string>

#include "tools/drive_monitor/live_bus.hpp"

namespace imd::monitor::cli {

struct WatchOptions {
  BusChoice bus;
  std::string log;
  std::string csv;
  int node = 1;
  bool table = false;
  bool no_table = false;
  double duration_s = 0.0;  ///< 0: until interrupted (live) or the end of the log
};

CLI::App* add_watch_command(CLI::App& app, WatchOptions& o);
int run_watch(const WatchOptions& o);

}  // namespace imd::monitor::cli
