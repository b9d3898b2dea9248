#pragma once
/// What happens on a fault of the processor itself (a hard fault, an interrupt nobody
/// handles, main returning): each target defines on_fatal_fault to put the power stage in its
/// safe state (PWM off) and report the reason, then stop. It must not return.
#include <cstdint>

namespace imd::hal::cortex_m {

enum class FatalFault : uint8_t {
  nmi,
  hard_fault,
  memory_management,
  bus_fault,
  usage_fault,
  unexpected_interrupt,
  main_returned,
  heap_use,  ///< something called malloc: there is no heap (hal/cortex_m/no_heap.cpp)
};

/// The name of a fatal fault, e.g. "hard_fault".
const char* fatal_fault_name(FatalFault fault) noexcept;

/// Defined by each target (firmware/cortex_m/...). Runs in handler mode; never returns.
[[noreturn]] void on_fatal_fault(FatalFault fault) noexcept;

}  // namespace imd::hal::cortex_m
