// drive_sim: runs a scenario of the drive firmware on the simulated board.
//
//   drive_sim SCENARIO.toml [--duration-s S] [--csv PATH] [--summary-json PATH]
//             [--plot PATH.png|.pdf|.svg] [--can-log PATH] [--set table.key=VALUE]...
//             [--motor-file PATH] [--motor-out PATH]
//
// Prints the summary (JSON) on standard output. Exit codes: 0 success, 2 bad input (command
// line or scenario file, an output path that cannot be written, or --plot without
// python3-matplotlib: all checked before the run), 1 an output could not be written during or
// after the run, 3 a commissioning run identified no motor (the summary says why).
#include <imd_version.hpp>
#include <fmt/format.h>
#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>

#include <cctype>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <iostream>
#include <optional>
#include <string>
#include <system_error>
#include <utility>
#include <vector>

#include <fcntl.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

extern char** environ;

#include "hal_sim/config_error.hpp"
#include "hal_sim/drive/scenario_run.hpp"
#include "hal_sim/drive/scripted_commands.hpp"
#include "hal_sim/motor_file.hpp"
#include "hal_sim/scenario.hpp"
#include "tools/can_log/candump_log.hpp"
#include "tools/data_path.hpp"
#include "tools/drive_sim/csv_writer.hpp"
#include "tools/drive_sim/summary_json.hpp"
#include "tools/output_path.hpp"

namespace {

constexpr int kExitBadInput = 2;
constexpr int kExitOutputFailed = 1;
constexpr int kExitNotIdentified = 3;

/// A commissioning run's outcome on standard error, and its motor file: 0, or the exit code.
int report_commissioning(const imd::sim::Scenario& s, const imd::sim::Summary& r,
                         const std::string& motor_out_path,
                         const std::vector<std::string>& overrides) {
  const auto& c = r.commissioning;
  if (!c || !c->identified) {
    std::string why = !c || !c->ended ? "the commissioning did not end within "
                                        "simulation.duration_s; give it more with --duration-s"
                                      : c->step + ", " + c->failure;
    if (!r.faults.empty()) why += "; fault " + r.faults.front().code;
    std::cerr << "drive_sim: no motor identified (" << why << ")"
              << (motor_out_path.empty() ? "" : ": " + motor_out_path + " not written") << '\n';
    return kExitNotIdentified;
  }
  const imd::sim::CommissioningSettings& n = *s.commissioning;
  std::string mechanics = "J and friction measured by the rotating step.";
  if (!c->mechanics_measured) {
    mechanics = c->failure == "no_motion"
                    ? "J and friction NOT measured: the rotor did not reach the test speed; J "
                      "is the catalogue rule's guess (docs/identification.md)."
                    : "J and friction NOT measured (standstill only): J is the catalogue rule's "
                      "guess (docs/identification.md); the speed loop's gains follow it.";
    std::cerr << "drive_sim: warning: " << mechanics << '\n';
  }
  if (motor_out_path.empty()) return 0;
  std::string settings;
  for (const std::string& o : overrides) settings += " --set " + o;
  const std::string text = imd::sim::motor_file_text(
      *c->identified, "identified by commissioning",
      fmt::format("Identified by drive_sim {}{}\n(nameplate {} V, {} A, {} Hz, pole pairs {}).\n"
                  "Lr = Ls by the convention of equal leakages (docs/identification.md).\n{}",
                  s.source, settings, n.rated_voltage_V, n.rated_current_A, n.rated_frequency_Hz,
                  n.pole_pairs, mechanics));
  std::FILE* file = std::fopen(motor_out_path.c_str(), "w");
  if (file == nullptr || std::fputs(text.c_str(), file) < 0 || std::fclose(file) != 0) {
    std::cerr << "drive_sim: cannot write " << motor_out_path << '\n';
    return kExitOutputFailed;
  }
  return 0;
}

/// The plot script for the scenario's controller: paper 000's figures or paper 001's, installed
/// beside drive_sim or in the source tree.
std::string plot_script(const imd::sim::Scenario& scenario) {
  const std::string name = scenario.controller == "iol" ? "plot_seed001.py" : "plot_seed000.py";
  return imd::tools::data_file("tools/" + name, "tools/" + name).string();
}

/// Runs a program with these arguments (no shell, so no quoting) and returns its exit status;
/// `quiet` sends its output to /dev/null.
int run_program(std::vector<std::string> args, bool quiet = false) {
  std::vector<char*> argv;
  for (std::string& arg : args) argv.push_back(arg.data());
  argv.push_back(nullptr);
  posix_spawn_file_actions_t actions;
  posix_spawn_file_actions_init(&actions);
  if (quiet) {
    posix_spawn_file_actions_addopen(&actions, 1, "/dev/null", O_WRONLY, 0);
    posix_spawn_file_actions_adddup2(&actions, 1, 2);
  }
  pid_t pid = 0;
  const int spawned = posix_spawn(&pid, argv[0], &actions, nullptr, argv.data(), environ);
  posix_spawn_file_actions_destroy(&actions);
  if (spawned != 0) return -1;
  int status = 0;
  if (waitpid(pid, &status, 0) < 0 || !WIFEXITED(status)) return -1;
  return WEXITSTATUS(status);
}

/// Why --plot PATH cannot be drawn, checked before the run: the format (what matplotlib's Agg
/// backend writes, by extension) and python3 with matplotlib and numpy. Empty: it can.
std::string plot_problem(const std::string& path) {
  std::string extension = std::filesystem::path(path).extension().string();
  for (char& c : extension) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  if (extension != ".png" && extension != ".pdf" && extension != ".svg") {  // out.PNG too
    return fmt::format("--plot {}: the file name must end in .png, .pdf or .svg", path);
  }
  if (run_program({"/usr/bin/python3", "-c", "import matplotlib, numpy"}, true) != 0) {
    return fmt::format("--plot {}: needs /usr/bin/python3 with matplotlib and numpy (Debian: "
                       "apt install python3-matplotlib)",
                       path);
  }
  return "";
}

/// --motor-file: an existing file, relative to the working directory (a scenario's motor files
/// are relative to the scenario's).
std::string model_file_problem(const std::string& path) {
  std::error_code status;
  if (std::filesystem::is_regular_file(path, status)) return "";
  return fmt::format("{}: no such file (a relative path is taken from the working directory, {})",
                     path, std::filesystem::current_path(status).string());
}

/// --duration-s: a simulated time in (0, 3600] s, as simulation.duration_s.
std::string duration_problem(const std::string& text) {
  double value = 0.0;
  try {
    std::size_t used = 0;
    value = std::stod(text, &used);
    if (used != text.size()) throw std::invalid_argument(text);
  } catch (const std::exception&) {
    return fmt::format("{} is not a number of seconds", text);
  }
  if (!(value > 0.0 && value <= 3600.0)) {
    return fmt::format("{} s: the simulated time must be > 0 and at most 3600 s", text);
  }
  return "";
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"Runs the drive firmware on the simulated board for a scenario file."};
  app.set_version_flag("--version", imd::version::kText);
  std::string scenario_path, csv_path, summary_path, plot_path, can_log_path, motor_out_path;
  std::optional<std::string> model_file;
  std::optional<double> duration_s;
  std::vector<std::string> overrides;
  app.add_option("scenario", scenario_path, "Scenario file (TOML)")->required();
  app.add_option("--duration-s", duration_s, "Simulated duration, overrides simulation.duration_s")
      ->check(CLI::Validator(duration_problem, "SECONDS in (0, 3600]"));
  app.add_option("--csv", csv_path, "Write one row per tick to this CSV file");
  app.add_option("--summary-json", summary_path, "Write the summary to this JSON file");
  app.add_option("--plot", plot_path,
                 "Write the paper's figures to this .png, .pdf or .svg (needs python3-matplotlib)");
  app.add_option("--can-log", can_log_path,
                 "Write every CAN frame on the bus to this file, as candump -L -x on the host's "
                 "interface can0 logs it: the firmware's frames received (R), the scenario's "
                 "commands transmitted (T), simulated time");
  app.add_option("--set", overrides, "Override a scenario key: table.key=VALUE (repeatable)");
  app.add_option("--motor-file", model_file,
                 "Give the controller this motor file instead of the scenario's motor; the "
                 "simulated motor stays the scenario's (e.g. an identified motor on the true "
                 "plant)")
      ->check(CLI::Validator(model_file_problem, "FILE"));
  app.add_option("--motor-out", motor_out_path,
                 "A commissioning scenario ([nameplate]): write the identified motor to this "
                 "motor file");
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& error) {
    const int code = app.exit(error);
    return code == 0 ? 0 : kExitBadInput;
  }
  // Each override names its own flag in messages: --duration-s is not a --set.
  std::vector<imd::sim::ScenarioOverride> flagged;
  for (const std::string& o : overrides) flagged.push_back({o, "--set " + o});
  if (duration_s) {
    overrides.push_back(fmt::format("simulation.duration_s={}", *duration_s));
    flagged.push_back({overrides.back(), fmt::format("--duration-s {}", *duration_s)});
  }
  for (const auto& [flag, path] : {std::pair{"--csv", &csv_path},
                                   {"--summary-json", &summary_path},
                                   {"--plot", &plot_path},
                                   {"--can-log", &can_log_path},
                                   {"--motor-out", &motor_out_path}}) {
    if (path->empty()) continue;
    if (const std::string problem = imd::tools::output_path_problem(flag, *path);
        !problem.empty()) {
      std::cerr << "drive_sim: " << problem << '\n';
      return kExitBadInput;
    }
  }
  if (!plot_path.empty()) {  // before a run that may be long, not after it
    if (const std::string problem = plot_problem(plot_path); !problem.empty()) {
      std::cerr << "drive_sim: " << problem << '\n';
      return kExitBadInput;
    }
  }

  imd::sim::Scenario scenario;
  try {
    scenario = imd::sim::load_scenario_with_flags(
        scenario_path, flagged,
        model_file ? std::optional<std::filesystem::path>(*model_file) : std::nullopt);
    if (!motor_out_path.empty() && !scenario.commissioning) {
      throw imd::sim::ConfigError(scenario_path +
                                  ": --motor-out needs a commissioning scenario ([nameplate])");
    }
    if (model_file && scenario.commissioning) {
      throw imd::sim::ConfigError(scenario_path +
                                  ": --motor-file: a commissioning scenario gives the drive no "
                                  "motor (it identifies one)");
    }
    imd::sim::scripted_frames(scenario);  // [[can_commands]] against the protocol table
  } catch (const imd::sim::ConfigError& error) {
    std::cerr << "drive_sim: " << error.what() << '\n';
    return kExitBadInput;
  }
  std::FILE* can_log = nullptr;
  if (!can_log_path.empty()) {
    can_log = std::fopen(can_log_path.c_str(), "w");
    if (can_log == nullptr) {
      std::cerr << "drive_sim: cannot write " << can_log_path << '\n';
      return kExitOutputFailed;
    }
  }

  // The plot is drawn from the CSV; without --csv a temporary file serves.
  const bool temporary_csv = csv_path.empty() && !plot_path.empty();
  if (temporary_csv)
    csv_path =
        (std::filesystem::temp_directory_path() / fmt::format("drive_sim_{}.csv", ::getpid()))
            .string();
  // Removed when main returns, whichever way.
  struct RemovedAtExit {
    std::string path;
    ~RemovedAtExit() {
      std::error_code ignored;
      if (!path.empty()) std::filesystem::remove(path, ignored);
    }
  } const temporary{temporary_csv ? csv_path : std::string()};
  std::FILE* csv = nullptr;
  std::optional<imd::tools::CsvWriter> csv_writer;
  if (!csv_path.empty()) {
    csv = std::fopen(csv_path.c_str(), "w");
    if (csv == nullptr) {
      std::cerr << "drive_sim: cannot write " << csv_path << '\n';
      return kExitOutputFailed;
    }
    csv_writer.emplace(csv);
    csv_writer->header();
  }

  imd::sim::RunCallbacks callbacks;
  if (csv_writer) {
    callbacks.row = [&csv_writer](const imd::sim::SimRow& r) { csv_writer->row(r); };
  }
  if (can_log != nullptr) {
    // The log reads as candump -L -x on the host's interface: the drive's frames received,
    // the scenario's commands transmitted.
    const auto log_frame = [&can_log](double t_s, const imd::hal::CanFrame& frame,
                                      imd::can_log::Direction direction) {
      const std::string line = imd::can_log::format_log_line(t_s, "can0", frame, direction);
      std::fprintf(can_log, "%s\n", line.c_str());
    };
    callbacks.can_frame = [log_frame](double t_s, const imd::hal::CanFrame& frame) {
      log_frame(t_s, frame, imd::can_log::Direction::received);
    };
    callbacks.host_frame = [log_frame](double t_s, const imd::hal::CanFrame& frame) {
      log_frame(t_s, frame, imd::can_log::Direction::transmitted);
    };
  }
  callbacks.progress = [&](double simulated_s, double wall_s) {
    std::fprintf(stderr, "\rdrive_sim: %.2f / %.2f s simulated, %.1f s wall", simulated_s,
                 scenario.duration_s, wall_s);
  };
  imd::sim::Summary summary;
  summary = imd::sim::run_scenario(scenario, callbacks);
  // A file that could not be written is reported, and the run's summary is still given: the
  // simulation itself did not fail.
  bool csv_written = !csv_writer || csv_writer->finish();
  if (csv != nullptr) csv_written = std::ferror(csv) == 0 && std::fclose(csv) == 0 && csv_written;
  const bool log_written =
      can_log == nullptr || (std::ferror(can_log) == 0 && std::fclose(can_log) == 0);
  if (summary.wall_time_s > 1.0 || !csv_written || !log_written) std::fprintf(stderr, "\n");
  if (!log_written) std::cerr << "drive_sim: cannot write " << can_log_path << " (disk full?)\n";
  if (!csv_written) std::cerr << "drive_sim: cannot write " << csv_path << " (disk full?)\n";

  const std::string text = imd::tools::summary_json(scenario, summary).dump(2);
  std::cout << text << '\n';
  if (!summary_path.empty()) {
    std::FILE* file = std::fopen(summary_path.c_str(), "w");
    if (file == nullptr || std::fprintf(file, "%s\n", text.c_str()) < 0 || std::fclose(file) != 0) {
      std::cerr << "drive_sim: cannot write " << summary_path << '\n';
      return kExitOutputFailed;
    }
  }
  if (scenario.commissioning) {
    const int status = report_commissioning(scenario, summary, motor_out_path, overrides);
    if (status != 0) return status;
  }
  if (!plot_path.empty() && csv_written) {  // no plot of a partial CSV
    std::string title = std::filesystem::path(scenario.source).filename().string();
    for (const std::string& o : overrides) title += " --set " + o;
    const int status = run_program({"/usr/bin/python3", plot_script(scenario), csv_path, "--out",
                                    plot_path, "--settle-s", fmt::format("{}", scenario.settle_s),
                                    "--title", title});
    if (status != 0) {
      std::cerr << "drive_sim: plotting failed (" << plot_script(scenario) << ", status " << status
                << "; it needs python3-matplotlib)\n";
      return kExitOutputFailed;
    }
  }
  return csv_written && log_written ? 0 : kExitOutputFailed;
}
