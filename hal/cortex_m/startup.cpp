/// Reset and the core's exception vectors, for every Cortex-M4F target. The linker script of
/// the target places `.isr_vector` (these 16 entries) at the start of flash, followed by the
/// chip's interrupt vectors (`.isr_vector.irq`, provided by the target) if it uses any.
///
/// Reset: paint the stack, copy .data from flash, zero .bss, give the core access to the FPU (before any float
/// instruction, so before the C++ constructors), run the constructors, then main().
#include <cstdint>

#include "hal/cortex_m/armv7m.hpp"
#include "hal/cortex_m/fault_handler.hpp"
#include "hal/cortex_m/stack_usage.hpp"

// Symbols of the linker script (hal/cortex_m/linker/*.ld).
extern "C" {
extern uint32_t __data_load_start__[], __data_start__[], __data_end__[];
extern uint32_t __bss_start__[], __bss_end__[];
extern uint32_t __stack_bottom__[], __stack_top__[];
extern void (*__preinit_array_start[])();
extern void (*__preinit_array_end[])();
extern void (*__init_array_start[])();
extern void (*__init_array_end[])();
int main();
[[noreturn]] void Reset_Handler();
void NMI_Handler();
void HardFault_Handler();
void MemManage_Handler();
void BusFault_Handler();
void UsageFault_Handler();
void SVC_Handler() __attribute__((weak, alias("Default_Handler")));
void DebugMon_Handler() __attribute__((weak, alias("Default_Handler")));
void PendSV_Handler() __attribute__((weak, alias("Default_Handler")));
void SysTick_Handler() __attribute__((weak, alias("Default_Handler")));
void Default_Handler();
}

namespace {

using Vector = void (*)();

}  // namespace

/// The core's vectors: initial stack pointer, reset, and the 14 system exceptions.
extern "C" __attribute__((section(".isr_vector"), used)) const Vector g_core_vectors[16] = {
    reinterpret_cast<Vector>(__stack_top__),
    Reset_Handler,
    NMI_Handler,
    HardFault_Handler,
    MemManage_Handler,
    BusFault_Handler,
    UsageFault_Handler,
    nullptr,
    nullptr,
    nullptr,
    nullptr,
    SVC_Handler,
    DebugMon_Handler,
    nullptr,
    PendSV_Handler,
    SysTick_Handler,
};

extern "C" void Reset_Handler() {
  // Paint the stack up to 64 bytes below this frame's stack pointer.
  uint32_t* const sp = static_cast<uint32_t*>(__builtin_frame_address(0));
  for (uint32_t* word = __stack_bottom__; word < sp - 16;) *word++ = imd::hal::cortex_m::kStackPaint;
  for (uint32_t *src = __data_load_start__, *dst = __data_start__; dst < __data_end__;) {
    *dst++ = *src++;
  }
  for (uint32_t* dst = __bss_start__; dst < __bss_end__;) *dst++ = 0;
  using namespace imd::hal::cortex_m;
  reg32(kScbCpacr) |= 0xFu << 20;  // CP10 and CP11: full access to the FPU
  data_sync_barrier();
  instruction_sync_barrier();
  for (auto f = __preinit_array_start; f < __preinit_array_end; ++f) (*f)();
  for (auto f = __init_array_start; f < __init_array_end; ++f) (*f)();
  // Calling main is what reset does on bare metal; ISO C++ reserves that to the runtime.
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wpedantic"
  main();
#pragma GCC diagnostic pop
  imd::hal::cortex_m::on_fatal_fault(imd::hal::cortex_m::FatalFault::main_returned);
}

// Every fault ends in the safe state: the target's handler turns the PWM off and reports.
extern "C" void NMI_Handler() {
  imd::hal::cortex_m::on_fatal_fault(imd::hal::cortex_m::FatalFault::nmi);
}
extern "C" void HardFault_Handler() {
  imd::hal::cortex_m::on_fatal_fault(imd::hal::cortex_m::FatalFault::hard_fault);
}
extern "C" void MemManage_Handler() {
  imd::hal::cortex_m::on_fatal_fault(imd::hal::cortex_m::FatalFault::memory_management);
}
extern "C" void BusFault_Handler() {
  imd::hal::cortex_m::on_fatal_fault(imd::hal::cortex_m::FatalFault::bus_fault);
}
extern "C" void UsageFault_Handler() {
  imd::hal::cortex_m::on_fatal_fault(imd::hal::cortex_m::FatalFault::usage_fault);
}
extern "C" void Default_Handler() {
  imd::hal::cortex_m::on_fatal_fault(imd::hal::cortex_m::FatalFault::unexpected_interrupt);
}
