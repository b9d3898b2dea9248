// Cost of one step of each control law, in float and double: the DSMC of paper 000, the
// input-output linearizing law of paper 001, and the deadbeat inner current step.
#include <benchmark/benchmark.h>

#include "control/deadbeat_current.hpp"
#include "control/dsmc.hpp"
#include "control/voltage_fed_model.hpp"
#include "control/current_fed_model.hpp"
#include "control/iol.hpp"
#include "tools/bench/bench_main.hpp"

namespace {

using imd::control::Vec2;

const imd::control::MotorParameters kPaper000{14.0, 0.4, 0.377, 10.1, 0.4128, 0.01, 1, 0.0};
const imd::control::MotorParameters kPaper001{0.052, 0.03175, 0.031, 0.07, 0.0323, 0.41, 2, 1e-4};

template <typename T>
void BM_DsmcStep(benchmark::State& bench) {
  const imd::control::Dsmc<T> law(imd::control::discretize_voltage_fed(kPaper000, 1e-4), {});
  imd::control::DsmcInput<T> in;
  in.flux_r_AB_Wb = {T(0.447), T(0.01)};
  in.i_s_AB_A = {T(1.19), T(2.0)};
  in.omega_mech_rad_s = T(50);
  in.omega_ref_rad_s = in.omega_ref_next_rad_s = T(50.01);
  in.flux2_ref_Wb2 = in.flux2_ref_next_Wb2 = T(0.2);
  in.feasible = {Vec2<T>(T(-5), T(20)), T(170)};
  for (auto _ : bench) {
    benchmark::DoNotOptimize(in);
    benchmark::DoNotOptimize(law.step(in));
  }
}
BENCHMARK_TEMPLATE(BM_DsmcStep, double)->Name("BM_DsmcStep/double");
BENCHMARK_TEMPLATE(BM_DsmcStep, float)->Name("BM_DsmcStep/float");

template <typename T>
void BM_IolStep(benchmark::State& bench) {
  const imd::control::Iol<T> law(imd::control::discretize_current_fed(kPaper001, 1e-3), {});
  imd::control::IolInput<T> in;
  in.flux_s_AB_Wb = {T(0.9), T(0.05)};
  in.i_s_AB_A = {T(30), T(100)};
  in.torque_ref_Nm = T(120);
  in.y2_ref = T(0.0018);
  for (auto _ : bench) {
    benchmark::DoNotOptimize(in);
    benchmark::DoNotOptimize(law.step(in));
  }
}
BENCHMARK_TEMPLATE(BM_IolStep, double)->Name("BM_IolStep/double");
BENCHMARK_TEMPLATE(BM_IolStep, float)->Name("BM_IolStep/float");

/// The worst case: the determinant guard bisects (stator flux 50 degrees ahead of phi_r,
/// 2000 N m asked).
template <typename T>
void BM_IolStepGuarded(benchmark::State& bench) {
  const auto c = imd::control::discretize_current_fed(kPaper001, 1e-3);
  const imd::control::Iol<T> law(c, {});
  imd::control::IolInput<T> in;
  in.flux_s_AB_Wb = {T(0.9), T(0)};
  const Vec2<double> flux_r(0.8 * 0.6427876, -0.8 * 0.7660444);
  in.i_s_AB_A = ((flux_r - c.flux_decay * Vec2<double>(0.9, 0.0)) / c.flux_from_i_now_H).cast<T>();
  in.torque_ref_Nm = T(2000);
  in.y2_ref = T(0.81 * (1 - c.flux_decay));
  if (!law.step(in).torque_limited) bench.SkipWithError("the guard did not act");
  for (auto _ : bench) {
    benchmark::DoNotOptimize(in);
    benchmark::DoNotOptimize(law.step(in));
  }
}
BENCHMARK_TEMPLATE(BM_IolStepGuarded, double)->Name("BM_IolStepGuarded/double");
BENCHMARK_TEMPLATE(BM_IolStepGuarded, float)->Name("BM_IolStepGuarded/float");

template <typename T>
void BM_DeadbeatCurrentStep(benchmark::State& bench) {
  const imd::control::DeadbeatCurrent<T> loop(imd::control::discretize_voltage_fed(kPaper001, 1e-4));
  const Vec2<T> flux(T(0.9), T(0.02)), current(T(30), T(95)), target(T(31), T(100));
  const imd::control::InputDisk<T> feasible{Vec2<T>(T(-10), T(40)), T(300)};
  for (auto _ : bench) {
    benchmark::DoNotOptimize(loop.input(flux, current, target, feasible));
  }
}
BENCHMARK_TEMPLATE(BM_DeadbeatCurrentStep, double)->Name("BM_DeadbeatCurrentStep/double");
BENCHMARK_TEMPLATE(BM_DeadbeatCurrentStep, float)->Name("BM_DeadbeatCurrentStep/float");

}  // namespace

int main(int argc, char** argv) { return imd::bench::run_benchmarks(argc, argv); }
