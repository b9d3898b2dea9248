#include "hal/cortex_m/fault_handler.hpp"

namespace imd::hal::cortex_m {

const char* fatal_fault_name(FatalFault fault) noexcept {
  switch (fault) {
    case FatalFault::nmi:
      return "nmi";
    case FatalFault::hard_fault:
      return "hard_fault";
    case FatalFault::memory_management:
      return "memory_management";
    case FatalFault::bus_fault:
      return "bus_fault";
    case FatalFault::usage_fault:
      return "usage_fault";
    case FatalFault::unexpected_interrupt:
      return "unexpected_interrupt";
    case FatalFault::main_returned:
      return "main_returned";
    case FatalFault::heap_use:
      return "heap_use";
  }
  return "unknown";
}

}  // namespace imd::hal::cortex_m
