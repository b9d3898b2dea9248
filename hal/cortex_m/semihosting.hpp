#pragma once
/// Arm semihosting: requests to a debugger or emulator attached to the core (QEMU with
/// -semihosting). Used only on an emulated MCU, to read its command line and to end the run
/// with an exit status; on a board without a debugger a request would halt the core, so board
/// images never call it.
#include <cstdint>

namespace imd::hal::cortex_m {

/// SYS_GET_CMDLINE: the command line the emulator was given (QEMU: -semihosting-config
/// enable=on,arg=...,arg=...), NUL-terminated in `buffer`. False when it does not fit.
bool semihosting_command_line(char* buffer, uint32_t size) noexcept;

/// SYS_EXIT_EXTENDED with ADP_Stopped_ApplicationExit: the emulator exits with `status`.
[[noreturn]] void semihosting_exit(int status) noexcept;

}  // namespace imd::hal::cortex_m
