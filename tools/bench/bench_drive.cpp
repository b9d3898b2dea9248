// Cost of the drive: simulated seconds per wall second for the seed-000 scenarios (firmware and
// plant together), and the control tick alone (the plant does not advance while it is timed).
#include <benchmark/benchmark.h>

#include <string>

#include "firmware/drive.hpp"
#include "hal_sim/scenario.hpp"
#include "hal_sim/sim_board.hpp"
#include "hal_sim/drive/scenario_run.hpp"

namespace {

std::string scenario_path(const char* name) {
  return std::string(IMD_SOURCE_DIR) + "/hal_sim/scenarios/" + name;
}

void BM_Scenario(benchmark::State& bench, const char* name, const char* precision) {
  const imd::sim::Scenario s = imd::sim::load_scenario(
      scenario_path(name), {"simulation.duration_s=1", "metrics.settle_s=0.5",
                            std::string("drive.precision=") + precision});
  double exec_ns = 0;
  for (auto _ : bench) {
    const imd::sim::Summary r = imd::sim::run_scenario(s);
    exec_ns = r.tick_exec_ns_mean;
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

/// The realistic drive, brought to the running state on the board, then ticked in place.
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
  imd::firmware::Drive<T> drive(
      s.motor, config, {board.pwm(), board.encoder(), board.adc(), board.timer()}, {&references});
  board.timer().start(drive);
  for (int k = 0; k < 5000 && drive.state() != imd::firmware::DriveState::running; ++k)
    board.run_tick();
  for (int k = 0; k < 2000; ++k) board.run_tick();
  if (drive.state() != imd::firmware::DriveState::running) bench.SkipWithError("drive not running");
  for (auto _ : bench) drive.on_tick();
  bench.SetItemsProcessed(bench.iterations());
}
BENCHMARK_TEMPLATE(BM_TickOnly, double)->Name("BM_TickOnly/double");
BENCHMARK_TEMPLATE(BM_TickOnly, float)->Name("BM_TickOnly/float");

}  // namespace

BENCHMARK_MAIN();
