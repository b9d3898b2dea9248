// The host's monotonic clock for the simulated board's execution clock (hal_sim/host_clock.hpp).
#include "hal_sim/host_clock.hpp"

#include <chrono>

namespace imd::sim {

uint64_t host_clock_ns() noexcept {
  return static_cast<uint64_t>(std::chrono::duration_cast<std::chrono::nanoseconds>(
                                   std::chrono::steady_clock::now().time_since_epoch())
                                   .count());
}

}  // namespace imd::sim
