// Cost of the drive: simulated seconds per wall second for the seed-000 scenarios (firmware and
// plant together), drive_sim's runs of the realistic scenario without output and with its CSV
// (the plant's integrators and the CSV's formatting methods, each against the one it replaced,
// in the same run), and the control tick alone (the plant does not advance while it is timed).
#include <benchmark/benchmark.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <optional>
#include <string>
#include <vector>

#include <unistd.h>

#include "firmware/drive.hpp"
#include "hal_sim/drive/scenario_run.hpp"
#include "hal_sim/scenario.hpp"
#include "hal_sim/sim_board.hpp"
#include "tools/bench/bench_main.hpp"
#include "tools/bench/reference_ifoc.hpp"
#include "tools/drive_sim/csv_writer.hpp"

namespace {

std::string scenario_path(const char* name) {
  return std::string(IMD_SOURCE_DIR) + "/hal_sim/scenarios/" + name;
}

/// A run that did not simulate what it should: every tick, the drive running, no fault.
const char* run_problem(const imd::sim::Scenario& s, const imd::sim::Summary& r) {
  if (r.ticks != uint64_t(s.duration_s / s.sample_period_s + 0.5)) return "the run ended early";
  if (r.running_from_s < 0.0) return "the drive never ran";
  if (!r.faults.empty()) return "the drive faulted";
  return nullptr;
}

void BM_Scenario(benchmark::State& bench, const char* name, const char* precision) {
  const imd::sim::Scenario s = imd::sim::load_scenario(
      scenario_path(name), {"simulation.duration_s=1", "metrics.settle_s=0.5",
                            std::string("drive.precision=") + precision});
  double exec_ns = 0;
  for (auto _ : bench) {
    const imd::sim::Summary r = imd::sim::run_scenario(s);
    exec_ns = r.tick_exec_ns_mean;
    if (const char* problem = run_problem(s, r)) {
      bench.SkipWithError(problem);
      break;
    }
    benchmark::DoNotOptimize(r);
  }
  // One iteration simulates 1 s.
  bench.counters["sim_s_per_wall_s"] =
      benchmark::Counter(double(bench.iterations()), benchmark::Counter::kIsRate);
  bench.counters["tick_exec_ns_mean"] = exec_ns;
}
BENCHMARK_CAPTURE(BM_Scenario, paper_double, "seed000_paper.toml", "double")
    ->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_Scenario, realistic_double, "seed000_realistic.toml", "double")
    ->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_Scenario, realistic_float, "seed000_realistic.toml", "float")
    ->Unit(benchmark::kMillisecond);

/// What drive_sim does for `hal_sim/scenarios/seed000_realistic.toml` (8 s), without output
/// files or with --csv: the plant integrated by `integrator`, the rows formatted by
/// `formatting` into a file in /tmp.
enum class Output { none, csv };
void BM_DriveSim(benchmark::State& bench, const char* integrator, Output output,
                 imd::tools::CsvFormatting formatting) {
  const imd::sim::Scenario s = imd::sim::load_scenario(
      scenario_path("seed000_realistic.toml"),
      {std::string("simulation.integrator=") + integrator});
  const std::string csv_path = "/tmp/bench_drive_" + std::to_string(::getpid()) + ".csv";
  for (auto _ : bench) {
    std::FILE* file = nullptr;
    std::optional<imd::tools::CsvWriter> csv;
    imd::sim::RunCallbacks callbacks;
    if (output == Output::csv) {
      file = std::fopen(csv_path.c_str(), "w");
      if (file == nullptr) {
        bench.SkipWithError("cannot write the CSV in /tmp");
        break;
      }
      csv.emplace(file, formatting);
      csv->header();
      callbacks.row = [&csv](const imd::sim::SimRow& r) { csv->row(r); };
    }
    const imd::sim::Summary r = imd::sim::run_scenario(s, callbacks);
    const bool written = !csv || (csv->finish() && std::fclose(file) == 0);
    if (const char* problem = written ? run_problem(s, r) : "the CSV was not written") {
      bench.SkipWithError(problem);
      break;
    }
  }
  std::remove(csv_path.c_str());
  bench.counters["sim_s_per_wall_s"] =
      benchmark::Counter(s.duration_s * double(bench.iterations()), benchmark::Counter::kIsRate);
}
using imd::tools::CsvFormatting;
// Wall time (UseRealTime): the threaded CSV's work is on a second thread.
BENCHMARK_CAPTURE(BM_DriveSim, rk4/no_output, "rk4", Output::none, CsvFormatting::buffered)
    ->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK_CAPTURE(BM_DriveSim, rk6/no_output, "rk6", Output::none, CsvFormatting::buffered)
    ->Unit(benchmark::kMillisecond)->UseRealTime();
// The CSV's methods in turn, each with the integrator it ran with: fmt per row (RK4),
// std::to_chars buffered (rk6), format_g10 buffered, and format_g10 on a second thread (what
// drive_sim does).
BENCHMARK_CAPTURE(BM_DriveSim, rk4_fmt_per_row/csv, "rk4", Output::csv,
                  CsvFormatting::fmt_per_row)
    ->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK_CAPTURE(BM_DriveSim, rk6_to_chars/csv, "rk6", Output::csv,
                  CsvFormatting::buffered_to_chars)
    ->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK_CAPTURE(BM_DriveSim, rk6_format_g10/csv, "rk6", Output::csv, CsvFormatting::buffered)
    ->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK_CAPTURE(BM_DriveSim, rk6_threaded/csv, "rk6", Output::csv, CsvFormatting::threaded)
    ->Unit(benchmark::kMillisecond)->UseRealTime();

/// The yardstick (tools/bench/reference_ifoc.hpp): a plain RK4 IFOC loop at 10 us on the
/// realistic scenario's motor, bus, current limit, flux, speed and load profiles, for as long.
/// The ratios below give drive_sim's speed against it, measured in the same run.
void BM_ReferenceIfoc(benchmark::State& bench) {
  const imd::sim::Scenario s = imd::sim::load_scenario(scenario_path("seed000_realistic.toml"));
  imd::bench::ReferenceIfocCase c;
  c.motor = s.motor;
  c.flux_Wb = std::sqrt(s.flux2_Wb2);
  c.v_max_V = s.v_bus_V / std::sqrt(3.0);
  c.i_max_A = s.i_max_A;
  c.duration_s = s.duration_s;
  c.sample_period_s = s.sample_period_s;
  c.substeps = 10;
  for (auto _ : bench) {
    const imd::bench::ReferenceIfocResult r = imd::bench::run_reference_ifoc(
        c, [&s](double t_s) { return s.speed.at(t_s); },
        [&s](double t_s) { return s.load.at(t_s); });
    // It must have driven the motor: a 10 Hz speed loop follows a 0.25 Hz sine of 100 rad/s
    // within a few rad/s (the load steps' dips included); a loop that did nothing would miss
    // by the sine's RMS, 71 rad/s.
    if (r.ticks != std::lround(c.duration_s / c.sample_period_s) ||
        !(r.speed_error_rms_rad_s < 10.0)) {
      bench.SkipWithError("the reference IFOC did not follow its speed reference");
      break;
    }
    bench.counters["speed_error_rms_rad_s"] = r.speed_error_rms_rad_s;
  }
  bench.counters["sim_s_per_wall_s"] =
      benchmark::Counter(c.duration_s * double(bench.iterations()), benchmark::Counter::kIsRate);
}
BENCHMARK(BM_ReferenceIfoc)->Unit(benchmark::kMillisecond)->UseRealTime();

/// The realistic drive, enabled and brought to the running state on the board; then each
/// iteration is one period, and only the tick is timed (manual time: the plant advances between
/// the clock reads, so that the running drive sees a moving motor; a drive ticked against a
/// still plant trips its encoder check). The figure includes one read of the monotonic clock.
template <typename T>
void BM_TickOnly(benchmark::State& bench) {
  const imd::sim::Scenario s = imd::sim::load_scenario(scenario_path("seed000_realistic.toml"));
  imd::sim::SimBoardConfig board_config;
  board_config.adc.full_scale_A = 10.0;
  board_config.adc.noise_A = 0.01;
  imd::sim::SimBoard board(s.motor, board_config);
  struct Constant final : imd::firmware::ReferenceSource<T> {
    imd::firmware::Reference<T> at_tick(uint64_t) const noexcept override {
      return {T(50), T(0.2)};
    }
  } references;
  imd::firmware::DriveConfig config;
  config.i_max_A = 6.0;
  config.speed_reaching_pole = config.flux_reaching_pole = 0.98;
  config.auto_enable = true;  // references from a profile: no enable command comes
  // The host is shared: a tick preempted for 90 us would trip the overrun check, which is not
  // what this measures.
  config.protection.tick_budget_ns = 0;
  imd::firmware::Drive<T> drive(
      s.motor, config, {board.pwm(), board.encoder(), board.adc(), board.timer()}, {&references});
  board.timer().start(drive);
  for (int k = 0; k < 20000 && drive.state() != imd::firmware::DriveState::running; ++k)
    board.run_tick();
  for (int k = 0; k < 2000; ++k) board.run_tick();
  if (drive.state() != imd::firmware::DriveState::running) {
    static std::string why;
    why = std::string("drive not running (fault ") + imd::firmware::fault_name(drive.fault()) + ")";
    bench.SkipWithError(why.c_str());
    return;
  }
  for (auto _ : bench) {
    board.begin_period();
    const auto start = std::chrono::steady_clock::now();
    board.fire_timer();  // the drive's tick, and the tick count advances as in a run
    const auto end = std::chrono::steady_clock::now();
    board.end_period();
    bench.SetIterationTime(std::chrono::duration<double>(end - start).count());
  }
  if (drive.state() != imd::firmware::DriveState::running) {
    static std::string why;
    why = std::string("the drive left the running state while timed (fault ") +
          imd::firmware::fault_name(drive.fault()) + ")";
    bench.SkipWithError(why.c_str());
  }
  bench.SetItemsProcessed(bench.iterations());
}
BENCHMARK_TEMPLATE(BM_TickOnly, double)->Name("BM_TickOnly/double")->UseManualTime();
BENCHMARK_TEMPLATE(BM_TickOnly, float)->Name("BM_TickOnly/float")->UseManualTime();

}  // namespace

int main(int argc, char** argv) {
  return imd::bench::run_benchmarks(
      argc, argv,
      {{"BM_DriveSim/rk4/no_output", "BM_DriveSim/rk6/no_output"},
       {"BM_DriveSim/rk4_fmt_per_row/csv", "BM_DriveSim/rk6_to_chars/csv"},
       {"BM_DriveSim/rk6_to_chars/csv", "BM_DriveSim/rk6_format_g10/csv"},
       {"BM_DriveSim/rk6_to_chars/csv", "BM_DriveSim/rk6_threaded/csv"},
       {"BM_DriveSim/rk6_to_chars/csv", "BM_DriveSim/rk6/no_output"},
       // drive_sim against the plain RK4 IFOC loop: below 1, drive_sim is the slower.
       {"BM_ReferenceIfoc", "BM_DriveSim/rk6/no_output"},
       {"BM_ReferenceIfoc", "BM_DriveSim/rk6_threaded/csv"}});
}
