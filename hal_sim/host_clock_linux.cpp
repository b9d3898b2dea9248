// The host's monotonic clock for the simulated board's execution clock (hal_sim/host_clock.hpp).
//
// The drive reads it two to four times a tick, so its cost is part of every simulation:
// steady_clock (the vDSO's clock_gettime) takes about 21 ns a read on x86-64, the time-stamp
// counter about 9 ns. The counter is used where the kernel itself keeps time with it (its
// clocksource is "tsc": the counter is invariant and in step across cores), scaled to ns by a
// rate measured once against steady_clock; elsewhere steady_clock is read.
#include "hal_sim/host_clock.hpp"

#include <chrono>
#include <cstdint>
#include <fstream>
#include <string>

#if defined(__x86_64__)
#include <x86intrin.h>
#endif

namespace imd::sim {
namespace {

uint64_t steady_ns() noexcept {
  return static_cast<uint64_t>(std::chrono::duration_cast<std::chrono::nanoseconds>(
                                   std::chrono::steady_clock::now().time_since_epoch())
                                   .count());
}

#if defined(__x86_64__)
__extension__ using u128 = unsigned __int128;  // GCC's and Clang's; -Wpedantic knows it not

/// ns = origin_ns + ((tsc - origin_tsc) * ns_per_tick_q32) >> 32.
struct TscScale {
  bool usable = false;
  uint64_t origin_tsc = 0, origin_ns = 0, ns_per_tick_q32 = 0;
};

bool kernel_keeps_time_with_tsc() {
  std::ifstream source("/sys/devices/system/clocksource/clocksource0/current_clocksource");
  std::string name;
  return static_cast<bool>(source >> name) && name == "tsc";
}

/// One pairing of the two clocks: the counter read between two steady_clock reads, the
/// narrowest of a few tries (a pair split by a preemption would skew the rate for the whole
/// process), the counter taken at their middle.
struct Pairing {
  uint64_t ns = 0, tsc = 0, width_ns = UINT64_MAX;
};
Pairing pair_clocks() {
  Pairing best;
  for (int attempt = 0; attempt < 8; ++attempt) {
    const uint64_t before = steady_ns(), tsc = __rdtsc(), after = steady_ns();
    if (after - before < best.width_ns) best = {before + (after - before) / 2, tsc, after - before};
  }
  return best;
}

TscScale calibrate() {
  TscScale scale;
  if (!kernel_keeps_time_with_tsc()) return scale;
  // 2 ms between two pairings, each within about its width (tens of ns when not preempted):
  // the rate is good to about 1e-4 on a loaded host, and a tick of a few microseconds is off
  // by well under a nanosecond.
  constexpr uint64_t kSpan_ns = 2'000'000;
  const Pairing first = pair_clocks();
  while (steady_ns() - first.ns < kSpan_ns) continue;  // spin: a sleep may overshoot a lot
  const Pairing last = pair_clocks();
  if (last.tsc <= first.tsc || first.width_ns > 10'000 || last.width_ns > 10'000) return scale;
  const auto q32 = static_cast<u128>(last.ns - first.ns) << 32;
  scale.ns_per_tick_q32 = static_cast<uint64_t>(q32 / (last.tsc - first.tsc));
  scale.origin_tsc = last.tsc;
  scale.origin_ns = last.ns;
  scale.usable = scale.ns_per_tick_q32 != 0;
  return scale;
}
#endif

}  // namespace

uint64_t host_clock_ns() noexcept {
#if defined(__x86_64__)
  static const TscScale scale = calibrate();  // once per process, thread-safe
  if (scale.usable) {
    const uint64_t tsc = __rdtsc();
    if (tsc <= scale.origin_tsc) return scale.origin_ns;  // never before the calibration's end
    const auto ns = static_cast<u128>(tsc - scale.origin_tsc) * scale.ns_per_tick_q32;
    return scale.origin_ns + static_cast<uint64_t>(ns >> 32);
  }
#endif
  return steady_ns();
}

}  // namespace imd::sim
