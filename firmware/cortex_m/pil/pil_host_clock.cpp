// The simulated board's own timer (SimTimer) is not used on the MCU: the SysTick timer of
// hal/cortex_m drives the tick and is the drive's execution clock. SimTimer is still linked
// (SimBoard holds one), so its clock must exist; nothing reads it.
#include "hal_sim/host_clock.hpp"

uint64_t imd::sim::host_clock_ns() noexcept { return 0; }
