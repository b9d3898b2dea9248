#pragma once
/// A reset cause that survives a system reset, for boards that keep none (the MPS2): written
/// just before an expected reset (the watchdog's NMI), read and cleared at the next start. It
/// lives in .noinit, which start-up neither loads nor zeroes; a magic word tells a record from
/// the RAM's power-on contents.
#include "hal/watchdog.hpp"

namespace imd::hal::cortex_m {

/// Records the cause of the reset about to happen.
void record_reset_cause(ResetCause cause) noexcept;
/// The cause recorded before this start (power_on if none), and clears it.
ResetCause take_reset_cause() noexcept;

}  // namespace imd::hal::cortex_m
