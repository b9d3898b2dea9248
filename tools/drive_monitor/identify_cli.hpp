#pragma once
/// drive_monitor identify: runs the commissioning on a live drive (its record must hold the
/// nameplate: drive_monitor parameters --set rated_voltage_V=...), shows the progress, and
/// reads back the identified record, optionally as a motor file.
#include <CLI/CLI.hpp>

#include <string>

#include "tools/drive_monitor/live_bus.hpp"

namespace imd::monitor::cli {

struct IdentifyOptions {
  BusChoice bus;
  int node = 1;
  bool rotate = false;    ///< also the rotating step (the shaft must be free to turn)
  std::string motor_out;  ///< write the identified record as a motor file
  double timeout_s = 600.0;
  double wait_s = 1.0;
  double wait_heartbeat_s = 0.5;
};

CLI::App* add_identify_command(CLI::App& app, IdentifyOptions& o);
int run_identify(const IdentifyOptions& o);

}  // namespace imd::monitor::cli
