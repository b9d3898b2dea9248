#include "hal/cortex_m/stack_usage.hpp"

extern "C" uint32_t __stack_bottom__[], __stack_top__[];

namespace imd::hal::cortex_m {

uint32_t stack_used_bytes() noexcept {
  const uint32_t* word = __stack_bottom__;
  while (word < __stack_top__ && *word == kStackPaint) ++word;
  return static_cast<uint32_t>(reinterpret_cast<uintptr_t>(__stack_top__) -
                               reinterpret_cast<uintptr_t>(word));
}

uint32_t stack_size_bytes() noexcept {
  return static_cast<uint32_t>(reinterpret_cast<uintptr_t>(__stack_top__) -
                               reinterpret_cast<uintptr_t>(__stack_bottom__));
}

}  // namespace imd::hal::cortex_m
