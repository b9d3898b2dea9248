// The host's monotonic clock for the simulated board's execution clock (hal_sim/host_clock.hpp).
//
// The drive reads it two to four times a tick, so its cost is part of every simulation:
// steady_clock (the vDSO's clock_gettime) takes about 21 ns a read on x86-64, the time-stamp
// counter about 9 ns. The counter is used where the kernel itself keeps time with it (its
// clocksource is "tsc": the counter is invariant and in step across cores), scaled to ns by a
// rate measured once against steady_clock; elsewhere steady_clock is read.
#include "hal_sim/host_clock.hpp"

#include <chrono>
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

TscScale calibrate() {
  TscScale scale;
  if (!kernel_keeps_time_with_tsc()) return scale;
  // 2 ms of both clocks: each read is within about 50 ns, so the rate is within 5e-5, and a
  // tick's few microseconds are off by well under a nanosecond.
  constexpr uint64_t kSpan_ns = 2'000'000;
  const uint64_t ns0 = steady_ns(), tsc0 = __rdtsc();
  uint64_t ns1 = ns0, tsc1 = tsc0;
  while (ns1 - ns0 < kSpan_ns) {
    ns1 = steady_ns();
    tsc1 = __rdtsc();
  }
  if (tsc1 <= tsc0) return scale;
  const auto q32 = static_cast<u128>(ns1 - ns0) << 32;
  scale.ns_per_tick_q32 = static_cast<uint64_t>(q32 / (tsc1 - tsc0));
  scale.origin_tsc = tsc1;
  scale.origin_ns = ns1;
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
