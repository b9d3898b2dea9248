// soak: a long simulated run under a random host and random faults, checking invariants every
// tick (tools/soak/soak_host.hpp; docs/safety-testing.md, "Soak"). Exit code 0 when no invariant was
// violated and the heap did not grow beyond the run's own fault log, 1 otherwise, 2 on bad
// arguments.
#include <imd_version.hpp>
#include <malloc.h>

#include <CLI/CLI.hpp>
#include <atomic>
#include <cstdio>
#include <cstdlib>
#include <new>
#include <string>

#include "hal_sim/config_error.hpp"
#include "hal_sim/drive/scenario_run.hpp"
#include "hal_sim/law_variant.hpp"
#include "hal_sim/scenario.hpp"
#include "tools/data_path.hpp"
#include "tools/soak/soak_host.hpp"

namespace {
// Live heap bytes, for the no-growth invariant (malloc_usable_size: what each block holds).
std::atomic<long long> g_live_bytes{0};
}  // namespace

void* operator new(std::size_t size) {
  void* p = std::malloc(size == 0 ? 1 : size);
  if (p == nullptr) throw std::bad_alloc();
  g_live_bytes += static_cast<long long>(malloc_usable_size(p));
  return p;
}
void operator delete(void* p) noexcept {
  if (p == nullptr) return;
  g_live_bytes -= static_cast<long long>(malloc_usable_size(p));
  std::free(p);
}
void operator delete(void* p, std::size_t) noexcept { operator delete(p); }

int main(int argc, char** argv) {
  CLI::App app{"Soak: a long simulated run under a random host and random faults, with the "
               "invariants checked every tick."};
  app.set_version_flag("--version", imd::version::kText);
  std::string scenario_file =  // installed beside soak, or in the source tree
      imd::tools::data_file("scenarios/seed000_can.toml", "hal_sim/scenarios/seed000_can.toml");
  std::string law = "dsmc", precision = "double";
  double seconds = 60.0, brake_Nm = -1.0;  // -1: sized from the motor and the board (below)
  uint64_t seed = 1;
  app.add_option("--scenario", scenario_file, "A CAN-commanded scenario file (the board)")
      ->check(CLI::ExistingFile);
  app.add_option("--law", law, "dsmc, ifoc or iol")->check(CLI::IsMember({"dsmc", "ifoc", "iol"}));
  app.add_option("--precision", precision, "double or float")
      ->check(CLI::IsMember({"double", "float"}));
  app.add_option("--seconds", seconds, "Simulated time")->check(CLI::Range(1.0, 1e6));
  app.add_option("--seed", seed, "Seed of the host, the faults and the ADC noise");
  app.add_option("--brake-Nm", brake_Nm,
                 "Holding brake fitted (0: none; default: the torque at the current limit)")
      ->check(CLI::NonNegativeNumber);
  CLI11_PARSE(app, argc, argv);

  imd::sim::Scenario s;
  try {
    s = imd::sim::with_law(
        imd::sim::load_scenario(scenario_file,
                                {"drive.precision=" + precision,
                                 "simulation.seed=" + std::to_string(seed % 1'000'000'000),
                                 "simulation.duration_s=" + std::to_string(seconds)}),
        law);
  } catch (const imd::sim::ConfigError& e) {
    std::fprintf(stderr, "soak: %s\n", e.what());
    return 2;
  }
  if (s.command_source != "can") {
    std::fprintf(stderr, "soak: %s: needs drive.command_source = \"can\"\n", scenario_file.c_str());
    return 2;
  }
  s.can_commands.clear();  // the soak host is the host
  s.faults.clear();
  // The host's loads reach half the torque at the current limit, either sign; a brake of the
  // whole of it holds them when the drive is off. Without one such a load runs the free rotor
  // up to over-speed (on the 15 kW test motor, from 0.8 of base speed, in about a second).
  s.brake.holding_torque_Nm = brake_Nm >= 0.0 ? brake_Nm : s.torque_limit_Nm;
  // Host time is not the MCU's: only a stall trips it. 1 s, because a loaded machine preempts a
  // tick for 100 ms and more; the injected stall (soak_host.cpp) is 2.5 times it.
  s.protection.tick_budget_us = 1e6;

  imd::soak::SoakHost host(s, seed);
  long long heap_after_warmup = -1, heap_end = 0;
  const double warmup_s = 0.1 * seconds;
  const imd::sim::Summary r = imd::sim::run_scenario(
      s, {[&](const imd::sim::SimRow& row) { host.after_tick(row); },
          [&](double simulated_s, double wall_s) {
            std::fprintf(stderr, "\rsoak: %.0f of %.0f s simulated (%.0f s)", simulated_s,
                         seconds, wall_s);
          },
          {},
          [&](uint64_t k, double t_s, imd::sim::SimBoard& board,
              const imd::firmware::DriveStatus& status) {
            if (heap_after_warmup < 0 && t_s >= warmup_s) heap_after_warmup = g_live_bytes;
            heap_end = g_live_bytes;
            host.before_tick(k, t_s, board, status);
          }});
  std::fprintf(stderr, "\n");
  const imd::soak::Counts& c = host.counts();
  // The run's fault log (Summary::faults) grows by an event per fault; a vector at most doubles
  // its capacity, and a code longer than the short-string buffer takes a block of its own.
  const long long log_bytes =
      static_cast<long long>(r.faults.size()) * (2 * long(sizeof(imd::sim::FaultEvent)) + 64);
  const long long growth = heap_end - heap_after_warmup;
  std::printf("soak: %s, %s, seed %llu, %.0f s simulated in %.0f s\n", law.c_str(),
              precision.c_str(), static_cast<unsigned long long>(seed), r.simulated_s,
              r.wall_time_s);
  std::printf("soak: %llu segments: %llu speed, %llu flux, %llu load, %llu invalid frames, "
              "%llu disables, %llu emergency stops, %llu faults (%llu detected with their code)\n",
              (unsigned long long)c.segments, (unsigned long long)c.speed,
              (unsigned long long)c.flux, (unsigned long long)c.load,
              (unsigned long long)c.invalid_frames, (unsigned long long)c.disables,
              (unsigned long long)c.emergency_stops, (unsigned long long)c.faults,
              (unsigned long long)c.detected);
  std::printf("soak: faults by kind:");
  for (int k = 0; k < imd::sim::kFaultKindCount; ++k) {
    std::printf(" %s %llu", imd::sim::fault_kind_name(imd::sim::FaultKind(k)),
                (unsigned long long)c.faults_by_kind[k]);
  }
  std::printf("\nsoak: heap after warm-up %lld B, at the end %lld B (growth %lld B, the fault log "
              "of %zu events allows %lld B)\n",
              heap_after_warmup, heap_end, growth, r.faults.size(), log_bytes);
  for (const std::string& v : host.violations()) std::printf("soak: violation at %s\n", v.c_str());
  const bool heap_ok = growth <= log_bytes;
  const bool ok = c.violations == 0 && heap_ok && r.ticks > 0;
  std::printf("soak: %llu invariant violations%s: %s\n", (unsigned long long)c.violations,
              heap_ok ? "" : ", the heap grew", ok ? "PASS" : "FAIL");
  return ok ? 0 : 1;
}
