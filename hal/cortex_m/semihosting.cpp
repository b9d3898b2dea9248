#include "hal/cortex_m/semihosting.hpp"

#include <cstdint>

namespace imd::hal::cortex_m {

bool semihosting_command_line(char* buffer, uint32_t size) noexcept {
  constexpr uint32_t kSysGetCmdline = 0x15;
  uint32_t block[2] = {reinterpret_cast<uint32_t>(buffer), size};
  register uint32_t operation asm("r0") = kSysGetCmdline;
  register uint32_t* argument asm("r1") = block;
  asm volatile("bkpt 0xab" : "+r"(operation) : "r"(argument) : "memory");
  return operation == 0;  // block[1] holds the length without the NUL
}

void semihosting_exit(int status) noexcept {
  constexpr uint32_t kSysExitExtended = 0x20;
  constexpr uint32_t kApplicationExit = 0x20026;  // ADP_Stopped_ApplicationExit
  const uint32_t block[2] = {kApplicationExit, static_cast<uint32_t>(status)};
  register uint32_t operation asm("r0") = kSysExitExtended;
  register const uint32_t* argument asm("r1") = block;
  asm volatile("bkpt 0xab" : : "r"(operation), "r"(argument) : "memory");
  for (;;) {
  }
}

}  // namespace imd::hal::cortex_m
