// drive_hil: the drive firmware on Linux in real time, against the simulated motor, commanded
// and watched over SocketCAN like a board (or, without SocketCAN, over TCP as a socketcand
// server: --can socketcand:[HOST:]PORT).
//
//   drive_hil SCENARIO.toml --can IFACE|socketcand:[HOST:]PORT --node N
//             [--gpio-chip NAME [--enable-line L] [--fault-line L] [--timing-line L]
//              [--enable-active-low]]
//             [--parameters PATH] [--duration-s S] [--latency-report PATH] [--priority P]
//             [--cpu C] [--set K=V]...
//
// The scenario gives the motor, the board and the drive's configuration. With --parameters the
// drive takes its motor parameters from that record file instead (as a board takes them from
// its flash), and a save over CAN writes it; a missing or invalid file leaves the drive
// unconfigured until a record is written over CAN. With a CAN interface
// the drive takes its references and enable only from CAN commands (and the enable line); the
// scenario's [[can_commands]] are not sent. `--can none` runs without a bus: the scenario's own
// reference profile drives the run (for latency measurements on a machine without CAN).
//
// The loop runs at the scenario's sample period (10 kHz) under SCHED_FIFO when permitted,
// with its memory locked. It runs until --duration-s has passed, or SIGINT or SIGTERM: then the
// PWM is turned off, a final heartbeat is sent and the report is written.
//
// Exit codes: 0 success, 1 the report could not be written or the plant diverged, 2 bad input
// (command line, scenario, CAN interface, GPIO chip or line).
#include <imd_version.hpp>
#include <CLI/CLI.hpp>
#include <fmt/format.h>

#include <array>
#include <csignal>
#include <cstdio>
#include <fstream>
#include <iostream>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "firmware/drive.hpp"
#include "firmware/linux/hil_report.hpp"
#include "firmware/linux/hil_tick.hpp"
#include "firmware/protocol/messages.hpp"
#include "hal_sim/drive/scenario_config.hpp"
#include "firmware/parameters/motor_record.hpp"
#include "hal/linux/file_parameter_store.hpp"
#include "hal/linux/gpiod_lines.hpp"
#include "firmware/linux/hil_can.hpp"
#include "hal/linux/realtime_timer.hpp"
#include "hal_sim/config_error.hpp"
#include "hal_sim/drive/simulated_drive.hpp"
#include "hal_sim/fault_injection.hpp"
#include "hal_sim/scenario.hpp"
#include "hal_sim/sim_board.hpp"

namespace {

constexpr int kExitFailed = 1;
constexpr int kExitBadInput = 2;
/// The protocol's one bit rate: a real CAN interface must be configured for it.
constexpr uint32_t kBitRate_bit_s = imd::firmware::protocol::kNominalBitrate_bit_s;
/// "1 Mbit/s", "500 kbit/s".
std::string bit_rate_text() {
  return kBitRate_bit_s % 1'000'000 == 0 ? fmt::format("{} Mbit/s", kBitRate_bit_s / 1'000'000)
                                         : fmt::format("{} kbit/s", kBitRate_bit_s / 1000);
}

struct Options {
  std::string scenario;
  std::string can;
  int node = 1;
  std::string gpio_chip;
  std::optional<int> enable_line, fault_line, timing_line;
  bool enable_active_low = false;
  std::optional<double> duration_s;
  std::string latency_report;
  std::string parameters;
  int priority = 80;
  int cpu = -1;
  std::vector<std::string> overrides;
};

int fail(const std::string& message, int code = kExitBadInput) {
  std::cerr << "drive_hil: " << message << '\n';
  return code;
}

/// The board's lines, in the order the drive's config indexes them.
struct Lines {
  std::vector<imd::hal::GpioLineSpec> specs;
  int enable = -1, fault = -1, timing = -1;
};

Lines board_lines(const Options& o) {
  Lines lines;
  auto add = [&lines](std::optional<int> offset, bool output, bool active_low, const char* role,
                      int& index) {
    if (!offset) return;
    index = static_cast<int>(lines.specs.size());
    lines.specs.push_back({static_cast<unsigned>(*offset), output, active_low, false, role});
  };
  add(o.enable_line, false, o.enable_active_low, "enable input", lines.enable);
  add(o.fault_line, true, false, "fault output", lines.fault);
  add(o.timing_line, true, false, "timing output", lines.timing);
  return lines;
}

/// Waits for SIGINT or SIGTERM (blocked in every thread, so they arrive here), the duration,
/// or the loop's own end. Returns why it stopped.
template <typename Stopped>
std::string wait_for_stop(const sigset_t& signals, std::optional<double> duration_s,
                          Stopped stopped) {
  const uint64_t start_ns = imd::hal::monotonic_ns();
  const timespec poll_interval{0, 10'000'000};  // 10 ms
  while (true) {
    const int signal = ::sigtimedwait(&signals, nullptr, &poll_interval);
    if (signal == SIGINT) return "SIGINT";
    if (signal == SIGTERM) return "SIGTERM";
    if (stopped()) return "plant diverged";
    if (duration_s && double(imd::hal::monotonic_ns() - start_ns) * 1e-9 >= *duration_s) {
      return "duration";
    }
  }
}

template <typename T>
int run(const Options& o, const imd::sim::Scenario& s, imd::firmware::HilCan* can,
        imd::hal::GpiodLines* gpio, const Lines& lines, const sigset_t& signals,
        std::vector<std::string> warnings) {
  using namespace imd;
  firmware::DriveConfig config = sim::drive_config(s);
  config.node_id = static_cast<uint8_t>(o.node);
  config.commands_over_can = can != nullptr;
  config.auto_enable = can == nullptr;
  // Real time: the tick's execution time is real, so its budget is checked (the scenario's, or
  // 90 % of the period: the firmware's default, 90 us, at 10 kHz).
  config.protection.tick_budget_ns = static_cast<uint32_t>(std::lround(
      s.protection.tick_budget_us ? *s.protection.tick_budget_us * 1e3
                                  : 0.9 * s.sample_period_s * 1e9));
  config.enable_input_line = lines.enable;
  config.fault_output_line = lines.fault;
  config.timing_output_line = lines.timing;

  sim::SimBoard board(s.plant, sim::board_config(s));
  sim::prepare_board(board, s);
  hal::RealtimeOptions timing;
  timing.period_ns = static_cast<uint32_t>(std::lround(s.sample_period_s * 1e9));
  timing.fifo_priority = o.priority;
  timing.cpu = o.cpu;
  hal::RealtimeTimer timer(timing);
  const sim::ScenarioReferences<T> references(s);
  std::optional<hal::FileParameterStore> file_store;
  if (!o.parameters.empty()) {
    file_store.emplace(o.parameters);
    std::array<uint8_t, firmware::kMotorRecordBytes> record{};
    const std::size_t n = file_store->load(record);
    if (n == 0) {
      warnings.push_back(file_store->last_error() + ": the drive starts unconfigured");
    } else if (!firmware::decode_motor_record(std::span<const uint8_t>(record).first(n))) {
      warnings.push_back(o.parameters + ": not a valid motor record of this firmware: the drive "
                         "starts unconfigured");
    }
  }
  sim::SimulatedDrive<T> simulated(
      board, s.motor, config, {s.ideal_sensors, s.inner_feedback, s.current_fed}, &references,
      timer, can != nullptr ? can->bus() : nullptr, gpio, file_store ? &*file_store : nullptr);
  firmware::Drive<T>& drive = simulated.drive();
  firmware::HilTick<T> tick(board, drive, s.faults);

  std::cerr << fmt::format("drive_hil: {} on {} as node {}, {} Hz, {} precision{}\n", s.source,
                           can == nullptr ? "no CAN bus"
                           : can->socketcand_address().empty()
                               ? fmt::format("{} at {}", can->name(), bit_rate_text())
                               : "socketcand " + can->socketcand_address(),
                           o.node,
                           std::lround(1.0 / s.sample_period_s), s.precision,
                           gpio != nullptr ? fmt::format(", GPIO {} ({} lines)", gpio->chip_name(),
                                                         gpio->size())
                                           : "");
  const uint64_t start_ns = hal::monotonic_ns();
  timer.start(tick);
  if (!timer.running()) return fail(timer.warning(), kExitFailed);
  if (!timer.warning().empty()) warnings.push_back(timer.warning());
  for (const std::string& w : warnings) std::cerr << "drive_hil: warning: " << w << '\n';
  // The main thread serves the drive's out-of-tick work (a new motor model, a save) while it
  // waits.
  const std::string reason = wait_for_stop(signals, o.duration_s, [&tick, &drive] {
    drive.service();
    return tick.plant_diverged();
  });
  timer.stop();
  drive.shut_down(timer.tick_count());
  if (can != nullptr && !can->flush(100)) warnings.push_back("CAN frames left unsent at the stop");

  firmware::HilRunFacts facts;
  facts.scenario = s.source;
  facts.stop_reason = reason;
  facts.period_ns = timing.period_ns;
  facts.wall_s = double(hal::monotonic_ns() - start_ns) * 1e-9;
  facts.ticks = timer.tick_count();
  facts.missed_periods = timer.missed_periods();
  facts.realtime = timer.realtime();
  facts.fifo_priority = o.priority;
  facts.warnings = warnings;
  facts.wakeup = &timer.wakeup_latency();
  facts.execution = &timer.execution_time();
  facts.state = firmware::state_name(drive.state());
  facts.first_fault = firmware::fault_name(drive.status().first_fault);
  facts.precision = s.precision;
  facts.drive_overruns = drive.execution().overruns;
  facts.telemetry_dropped = drive.telemetry().dropped_frames();
  facts.can_iface = "none";
  if (can != nullptr) can->report(facts);
  std::cout << firmware::report_text(facts) << std::flush;

  int status = reason == "plant diverged" ? kExitFailed : 0;
  if (status != 0) std::cerr << "drive_hil: the simulated plant diverged (NaN): run stopped\n";
  if (!o.latency_report.empty()) {
    std::ofstream file(o.latency_report, std::ios::trunc);
    file << firmware::report_json(facts).dump(2) << '\n';
    if (!file.flush()) {
      std::cerr << "drive_hil: cannot write " << o.latency_report << '\n';
      status = kExitFailed;
    }
  }
  return status;
}

}  // namespace

int main(int argc, char** argv) {
  Options o;
  CLI::App app{"Runs the drive firmware in real time against the simulated motor, over CAN."};
  app.set_version_flag("--version", imd::version::kText);
  app.add_option("scenario", o.scenario, "Scenario file (TOML)")->required();
  app.add_option("--can", o.can,
                 fmt::format("SocketCAN interface, e.g. can0 (configured for the protocol's {}, "
                             "else refused) or vcan0; socketcand:[HOST:]PORT: serve the bus over "
                             "TCP in the socketcand protocol, for a machine without SocketCAN "
                             "(host 127.0.0.1 unless given; port 0: any free one); 'none': no "
                             "bus",
                             bit_rate_text()))
      ->required();
  app.add_option("--node", o.node, "CAN node id")
      ->check(CLI::Range(0, imd::firmware::protocol::kMaxNodeId));
  auto* chip = app.add_option("--gpio-chip", o.gpio_chip,
                              "GPIO chip: name (gpiochip0), path, number or label");
  auto line = [&](const char* name, std::optional<int>& offset, const char* what) {
    return app.add_option(name, offset, what)->check(CLI::Range(0, 1023))->needs(chip);
  };
  line("--enable-line", o.enable_line, "Hardware enable input line (offset on the chip)");
  line("--fault-line", o.fault_line, "Fault output line: high while a fault is latched");
  line("--timing-line", o.timing_line, "Timing output line: high while the tick computes");
  app.add_flag("--enable-active-low", o.enable_active_low,
               "The enable input is active when the line is low");
  app.add_option("--parameters", o.parameters,
                 "Motor parameter record file: loaded at start, written by a save over CAN");
  app.add_option("--duration-s", o.duration_s, "Stop after this many wall-clock seconds")
      ->check(CLI::Range(1e-3, 1e7));
  app.add_option("--latency-report", o.latency_report,
                 "Write the loop's timing histograms and the run's counters to this JSON file");
  app.add_option("--priority", o.priority, "SCHED_FIFO priority of the loop; 0: normal scheduler")
      ->check(CLI::Range(0, 99));
  app.add_option("--cpu", o.cpu, "Pin the loop to this CPU")->check(CLI::NonNegativeNumber);
  app.add_option("--set", o.overrides, "Override a scenario key: table.key=VALUE (repeatable)");
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& error) {
    const int code = app.exit(error);
    return code == 0 ? 0 : kExitBadInput;
  }
  if (!o.gpio_chip.empty() && !o.enable_line && !o.fault_line && !o.timing_line) {
    return fail("--gpio-chip " + o.gpio_chip + " given without any line to use");
  }

  imd::sim::Scenario scenario;
  try {
    scenario = imd::sim::load_scenario(o.scenario, o.overrides);
  } catch (const imd::sim::ConfigError& error) {
    return fail(error.what());
  }
  // The faults are checked here, before the loop: in the tick the board would skip them.
  for (const imd::sim::FaultInjection& fault : scenario.faults) {
    if (const char* error = imd::sim::fault_parameter_error(fault)) {
      return fail(o.scenario + ": " + error);
    }
  }
  std::vector<std::string> warnings;
  const bool with_can = o.can != "none";
  if (!with_can && scenario.command_source == "can") {
    return fail(o.scenario + ": takes its speed from CAN commands; give a CAN interface");
  }
  if (with_can && !scenario.can_commands.empty()) {
    warnings.push_back(fmt::format("{}: its {} [[can_commands]] are not sent: the host commands "
                                   "the drive over {}",
                                   o.scenario, scenario.can_commands.size(), o.can));
  }

  // SIGINT and SIGTERM are blocked before any thread starts, so that every thread inherits the
  // mask and the main thread takes them with sigtimedwait: no handler runs inside the loop.
  sigset_t signals;
  sigemptyset(&signals);
  sigaddset(&signals, SIGINT);
  sigaddset(&signals, SIGTERM);
  pthread_sigmask(SIG_BLOCK, &signals, nullptr);

  std::string error;
  std::unique_ptr<imd::firmware::HilCan> can;
  if (with_can) {
    const std::optional<imd::firmware::HilCanSpec> spec =
        imd::firmware::parse_hil_can(o.can, error);
    if (!spec) return fail(error);
    // One write per line: the I/O thread's lines never interleave with the main thread's.
    auto log = [](const std::string& text) {
      std::cerr << "drive_hil: socketcand: " + text + "\n";
    };
    can = imd::firmware::HilCan::open(*spec, o.node, kBitRate_bit_s, error, log);
    if (!can) return fail(error);
    if (spec->socketcand) {
      log(fmt::format("listening on {} (raw mode), e.g. imdrive watch --socketcand {}",
                      can->socketcand_address(), can->socketcand_address()));
    }
  }
  const Lines lines = board_lines(o);
  std::unique_ptr<imd::hal::GpiodLines> gpio;
  if (!lines.specs.empty()) {
    gpio = imd::hal::GpiodLines::open(o.gpio_chip, lines.specs, "drive_hil", error);
    if (!gpio) return fail(error);
  }
  const std::string memory_warning = imd::hal::lock_memory();
  if (!memory_warning.empty()) warnings.push_back(memory_warning);
  const imd::hal::CpuIdleLatencyRequest idle_latency;
  if (!idle_latency.warning().empty()) warnings.push_back(idle_latency.warning());

  return scenario.precision == "float"
             ? run<float>(o, scenario, can.get(), gpio.get(), lines, signals, warnings)
             : run<double>(o, scenario, can.get(), gpio.get(), lines, signals, warnings);
}
