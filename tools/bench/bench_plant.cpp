// Cost of the continuous plant: one right-hand-side evaluation of model (1), and one period
// step (10 kHz period) in each of the plant's three input modes: RK4 for several substep counts,
// and RK4 at 10 substeps against the sixth-order integrator (hal_sim/plant_integrator.hpp) at
// several speeds (its step count grows with the speed), their ratio printed at the end. And the
// simulated board's execution clock (hal_sim/host_clock.hpp), read two to four times a tick,
// against the steady_clock it replaced.
#include <benchmark/benchmark.h>

#include <chrono>
#include <cmath>

#include "hal_sim/host_clock.hpp"
#include "hal_sim/induction_motor_plant.hpp"
#include "tools/bench/bench_main.hpp"

namespace {

using imd::sim::PlantIntegrator;

imd::control::MotorParameters paper_motor() {
  return {14.0, 0.4, 0.377, 10.1, 0.4128, 0.01, 1, 0.0};
}

imd::sim::PlantState running_state(double omega_mech_rad_s = 100.0) {
  imd::sim::PlantState s;
  s.flux_r_alphabeta_Wb = {0.4, 0.1};
  s.i_s_alphabeta_A = {1.5, -0.7};
  s.omega_mech_rad_s = omega_mech_rad_s;
  s.theta_mech_rad = 0.3;
  return s;
}

void BM_PlantDerivative(benchmark::State& bench) {
  const imd::sim::InductionMotorPlant plant(paper_motor(), {});
  imd::sim::InductionMotorPlant::StateVector x;
  x << 0.4, 0.1, 1.5, -0.7, 100.0, 0.3;
  const imd::sim::Vec2 u(120.0, -40.0);
  imd::sim::InductionMotorPlant::StateVector dx = x;
  for (auto _ : bench) {
    benchmark::DoNotOptimize(x);
    dx = plant.voltage_fed_derivative(x, u, 0.5);
    benchmark::DoNotOptimize(dx);
  }
  if (!dx.allFinite() || dx.norm() == 0.0) bench.SkipWithError("the derivative is zero or not finite");
  bench.SetItemsProcessed(bench.iterations());
}
BENCHMARK(BM_PlantDerivative);

/// One period from the same state each iteration; the state must have moved and stay finite.
template <int Mode>
void period(benchmark::State& bench, imd::sim::InductionMotorPlant& plant,
            const imd::sim::PlantState& start) {
  const imd::sim::Vec2 input(120.0, -40.0);
  const imd::sim::Vec2 current(1.0, 2.0);
  for (auto _ : bench) {
    plant.set_state(start);
    if constexpr (Mode == 0) plant.step_voltage(input, 0.5);
    if constexpr (Mode == 1) plant.step_analog_feedback(input, 0.5);
    if constexpr (Mode == 2) plant.step_current_fed(current, 0.5);
    benchmark::DoNotOptimize(plant.state());
  }
  const imd::sim::PlantState& end = plant.state();
  if (!end.flux_r_alphabeta_Wb.allFinite() || !end.i_s_alphabeta_A.allFinite() ||
      !std::isfinite(end.omega_mech_rad_s) ||
      (end.i_s_alphabeta_A - start.i_s_alphabeta_A).norm() == 0.0 ||
      end.theta_mech_rad == start.theta_mech_rad) {
    bench.SkipWithError("the period did not move the plant");
  }
  bench.SetItemsProcessed(bench.iterations());
}

/// RK4 with range(0) substeps.
template <int Mode>
void BM_PlantPeriod(benchmark::State& bench) {
  imd::sim::PlantConfig config;
  config.period_s = 1e-4;
  config.rk4_substeps = static_cast<int>(bench.range(0));
  imd::sim::InductionMotorPlant plant(paper_motor(), config);
  period<Mode>(bench, plant, running_state());
}
BENCHMARK(BM_PlantPeriod<0>)->Name("BM_PlantPeriod/voltage_fed")->Arg(1)->Arg(10)->Arg(100);
BENCHMARK(BM_PlantPeriod<1>)->Name("BM_PlantPeriod/analog_feedback")->Arg(1)->Arg(10)->Arg(100);
BENCHMARK(BM_PlantPeriod<2>)->Name("BM_PlantPeriod/current_fed")->Arg(1)->Arg(10)->Arg(100);

/// The integrator `Integrator` (RK4 at 10 substeps, or rk6) at the speed range(0) rad/s.
template <int Mode, PlantIntegrator Integrator>
void BM_PlantIntegrator(benchmark::State& bench) {
  imd::sim::InductionMotorPlant plant(paper_motor(), {1e-4, 10, Integrator});
  period<Mode>(bench, plant, running_state(double(bench.range(0))));
}
#define IMD_PLANT_INTEGRATOR(mode, name)                                           \
  BENCHMARK(BM_PlantIntegrator<mode, PlantIntegrator::rk4>)                        \
      ->Name("BM_PlantIntegrator/rk4/" name)->Arg(0)->Arg(100)->Arg(300);          \
  BENCHMARK(BM_PlantIntegrator<mode, PlantIntegrator::rk6>)                        \
      ->Name("BM_PlantIntegrator/rk6/" name)->Arg(0)->Arg(100)->Arg(300)
IMD_PLANT_INTEGRATOR(0, "voltage_fed");
IMD_PLANT_INTEGRATOR(1, "analog_feedback");
IMD_PLANT_INTEGRATOR(2, "current_fed");
#undef IMD_PLANT_INTEGRATOR

/// One read of a clock; fails if it went backwards or stood still over the whole run.
template <typename Read>
void read_clock(benchmark::State& bench, Read read) {
  const uint64_t first = read();
  uint64_t last = first;
  bool backwards = false;
  for (auto _ : bench) {
    const uint64_t now = read();
    backwards |= now < last;
    last = now;
    benchmark::DoNotOptimize(last);
  }
  if (backwards) bench.SkipWithError("the clock went backwards");
  if (last == first) bench.SkipWithError("the clock did not move");
}
void BM_Clock_steady(benchmark::State& bench) {
  read_clock(bench, [] {
    return uint64_t(std::chrono::duration_cast<std::chrono::nanoseconds>(
                        std::chrono::steady_clock::now().time_since_epoch())
                        .count());
  });
}
BENCHMARK(BM_Clock_steady);
void BM_Clock_host_clock_ns(benchmark::State& bench) {
  read_clock(bench, [] { return imd::sim::host_clock_ns(); });
}
BENCHMARK(BM_Clock_host_clock_ns);

}  // namespace

int main(int argc, char** argv) {
  return imd::bench::run_benchmarks(
      argc, argv,
      {{"BM_PlantIntegrator/rk4/", "BM_PlantIntegrator/rk6/"},
       {"BM_Clock_steady", "BM_Clock_host_clock_ns"}});
}
