/// The C++ runtime hooks of a firmware without heap and without exit.
///
/// There is no heap. operator new is deliberately left undefined, so any allocation by new
/// fails to link, and so does any throw (cmake/CortexM.cmake). The C allocator is wrapped
/// (--wrap=malloc, ...) to the traps below: Eigen's fixed-size algorithms name aligned_malloc as
/// the fallback for a temporary larger than EIGEN_STACK_ALLOCATION_LIMIT (128 KiB), which
/// their small fixed-size matrices never need; newlib's allocator is therefore never linked, and a call would be a
/// fatal fault. tools/check_tick_path.py proves that the tick cannot reach any of them.
#include <cstddef>

#include "hal/cortex_m/fault_handler.hpp"

using imd::hal::cortex_m::FatalFault;
using imd::hal::cortex_m::on_fatal_fault;

// Virtual destructors would make the compiler emit "deleting" destructors, which name
// operator delete; the project's interfaces have none, but a deleting destructor elsewhere
// must not pull in the allocator. Nothing is ever allocated, so nothing is ever deleted.
void operator delete(void*) noexcept { on_fatal_fault(FatalFault::heap_use); }
void operator delete(void*, std::size_t) noexcept { on_fatal_fault(FatalFault::heap_use); }

extern "C" {
void* __wrap_malloc(std::size_t) { on_fatal_fault(FatalFault::heap_use); }
void __wrap_free(void*) { on_fatal_fault(FatalFault::heap_use); }
void* __wrap_calloc(std::size_t, std::size_t) { on_fatal_fault(FatalFault::heap_use); }
void* __wrap_realloc(void*, std::size_t) { on_fatal_fault(FatalFault::heap_use); }
void* __wrap_memalign(std::size_t, std::size_t) { on_fatal_fault(FatalFault::heap_use); }
void* __wrap__malloc_r(void*, std::size_t) { on_fatal_fault(FatalFault::heap_use); }
void __wrap__free_r(void*, void*) { on_fatal_fault(FatalFault::heap_use); }
void* __wrap__calloc_r(void*, std::size_t, std::size_t) { on_fatal_fault(FatalFault::heap_use); }
void* __wrap__realloc_r(void*, void*, std::size_t) { on_fatal_fault(FatalFault::heap_use); }
void* __wrap__memalign_r(void*, std::size_t, std::size_t) {
  on_fatal_fault(FatalFault::heap_use);
}

// A call of a pure virtual function (only possible from a constructor or destructor).
void __cxa_pure_virtual() { on_fatal_fault(FatalFault::usage_fault); }
// Static objects register their destructors; the firmware never exits, so none is kept.
int __cxa_atexit(void (*)(void*), void*, void*) { return 0; }
void* __dso_handle = nullptr;
}
