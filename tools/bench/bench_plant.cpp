// Cost of the continuous plant: one right-hand-side evaluation of model (1), and one RK4 period
// step (10 kHz period) for several substep counts, in each of the plant's three input modes.
#include <benchmark/benchmark.h>

#include "hal_sim/induction_motor_plant.hpp"

namespace {

imd::control::MotorParameters paper_motor() {
  return {14.0, 0.4, 0.377, 10.1, 0.4128, 0.01, 1, 0.0};
}

imd::sim::PlantState running_state() {
  imd::sim::PlantState s;
  s.flux_r_alphabeta_Wb = {0.4, 0.1};
  s.i_s_alphabeta_A = {1.5, -0.7};
  s.omega_mech_rad_s = 100.0;
  s.theta_mech_rad = 0.3;
  return s;
}

void BM_PlantDerivative(benchmark::State& bench) {
  const imd::sim::InductionMotorPlant plant(paper_motor(), {});
  imd::sim::InductionMotorPlant::StateVector x;
  x << 0.4, 0.1, 1.5, -0.7, 100.0, 0.3;
  const imd::sim::Vec2 u(120.0, -40.0);
  for (auto _ : bench) {
    benchmark::DoNotOptimize(x);
    auto dx = plant.voltage_fed_derivative(x, u, 0.5);
    benchmark::DoNotOptimize(dx);
  }
  bench.SetItemsProcessed(bench.iterations());
}
BENCHMARK(BM_PlantDerivative);

template <int Mode>
void BM_PlantPeriod(benchmark::State& bench) {
  imd::sim::PlantConfig config;
  config.period_s = 1e-4;
  config.rk4_substeps = static_cast<int>(bench.range(0));
  imd::sim::InductionMotorPlant plant(paper_motor(), config);
  const imd::sim::Vec2 input(120.0, -40.0);
  const imd::sim::Vec2 current(1.0, 2.0);
  for (auto _ : bench) {
    plant.set_state(running_state());
    if constexpr (Mode == 0) plant.step_voltage(input, 0.5);
    if constexpr (Mode == 1) plant.step_analog_feedback(input, 0.5);
    if constexpr (Mode == 2) plant.step_current_fed(current, 0.5);
    benchmark::DoNotOptimize(plant.state());
  }
  bench.SetItemsProcessed(bench.iterations());
}
BENCHMARK(BM_PlantPeriod<0>)->Name("BM_PlantPeriod/voltage_fed")->Arg(1)->Arg(10)->Arg(100);
BENCHMARK(BM_PlantPeriod<1>)->Name("BM_PlantPeriod/analog_feedback")->Arg(1)->Arg(10)->Arg(100);
BENCHMARK(BM_PlantPeriod<2>)->Name("BM_PlantPeriod/current_fed")->Arg(1)->Arg(10)->Arg(100);

}  // namespace

BENCHMARK_MAIN();
