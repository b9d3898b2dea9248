#pragma once
/// The stack's high-water mark. Reset paints the stack with a pattern (below the frame of the
/// start-up code); the deepest word that no longer holds it bounds what was ever used.
#include <cstdint>

namespace imd::hal::cortex_m {

inline constexpr uint32_t kStackPaint = 0xC5AC'CE55u;

/// Bytes of stack used so far (an upper bound: a pushed word equal to the pattern would hide).
uint32_t stack_used_bytes() noexcept;
/// The stack's size (the target linker script's STACK_SIZE).
uint32_t stack_size_bytes() noexcept;

}  // namespace imd::hal::cortex_m
