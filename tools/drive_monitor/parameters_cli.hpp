#pragma once
/// drive_monitor parameters: reads the drive's motor record, writes fields (KEY=VALUE, or all of
/// a motor file), saves it to the drive's storage, and writes what the drive holds as a motor
/// file.
#include <CLI/CLI.hpp>

#include <string>

#include <vector>
#include "tools/drive_monitor/live_bus.hpp"

namespace imd::monitor::cli {

struct ParametersOptions {
  BusChoice bus;
  int node = 1;
  std::vector<std::string> sets;  ///< KEY=VALUE, in order
  std::string motor_file;         ///< every field from this motor file
  bool save = false;
  std::string motor_out;  ///< write the record read back as a motor file
  double wait_s = 1.0;    ///< per answer (a write is answered once the drive has checked it)
  double wait_heartbeat_s = 0.5;
};

CLI::App* add_parameters_command(CLI::App& app, ParametersOptions& o);
int run_parameters(const ParametersOptions& o);

}  // namespace imd::monitor::cli
