#pragma once
/// Arm semihosting: requests to a debugger or emulator attached to the core (QEMU with
/// -semihosting). Used only to end a run on an emulated MCU with an exit status; on a board
/// without a debugger the request would halt the core, so board images never call it.
namespace imd::hal::cortex_m {

/// SYS_EXIT_EXTENDED with ADP_Stopped_ApplicationExit: the emulator exits with `status`.
[[noreturn]] void semihosting_exit(int status) noexcept;

}  // namespace imd::hal::cortex_m
