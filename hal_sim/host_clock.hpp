#pragma once
/// The monotonic clock behind SimTimer::execution_counts(). Declared here, defined once per
/// target and chosen at link time: on Linux, hal_sim/host_clock_linux.cpp (the time-stamp counter, or steady_clock) comes
/// with the library imd_hal_sim; a bare-metal image links imd_hal_sim_core alone and must
/// define it itself (e.g. from the DWT cycle counter), or its link fails. The core stays free
/// of <chrono>, which has no clock on the MCU.
#include <cstdint>

namespace imd::sim {

/// Nanoseconds since an arbitrary origin; never decreases. Tick context: must be cheap and
/// must not block, once it has been read a first time outside a tick (an implementation may
/// calibrate itself then; SimTimer's constructor does that read).
uint64_t host_clock_ns() noexcept;

}  // namespace imd::sim
