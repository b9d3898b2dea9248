// Minimal start-up shared by the fixtures: the core's vector table, Reset_Handler (which runs
// the fixture's initialization, where double is allowed) and default handlers. A fixture
// defines SysTick_Handler/PendSV_Handler (the tick roots) and fixture_init().
using Vector = void (*)();

extern "C" {
extern unsigned __stack_top[];  // fixture_*.ld
[[noreturn]] void Reset_Handler();
void Default_Handler();
void HardFault_Handler() __attribute__((weak, alias("Default_Handler")));
void SVC_Handler() __attribute__((weak, alias("Default_Handler")));
void PendSV_Handler() __attribute__((weak, alias("Default_Handler")));
void SysTick_Handler() __attribute__((weak, alias("Default_Handler")));
void ADC_IRQHandler() __attribute__((weak, alias("Default_Handler")));
void TIM2_IRQHandler() __attribute__((weak, alias("Default_Handler")));
void fixture_init();
}

// Deliberately not one of the checker's well-known vector table names: with fixture_text.ld
// it must be recognised because its second word is the entry point.
extern "C" __attribute__((section(".isr_vector"), used)) const Vector fixture_vector_table[16] = {
    reinterpret_cast<Vector>(__stack_top),
    Reset_Handler,
    Default_Handler,  // NMI
    HardFault_Handler,
    Default_Handler,  // MemManage
    Default_Handler,  // BusFault
    Default_Handler,  // UsageFault
    nullptr,
    nullptr,
    nullptr,
    nullptr,
    SVC_Handler,
    Default_Handler,  // DebugMon
    nullptr,
    PendSV_Handler,
    SysTick_Handler,
};

// The chip's interrupt vectors, right after the core's (as hal/cortex_m/startup.cpp describes).
extern "C" __attribute__((section(".isr_vector.irq"), used)) const Vector fixture_irq_vectors[2] = {
    ADC_IRQHandler,
    TIM2_IRQHandler,
};

extern "C" {
void Reset_Handler() {
  fixture_init();
  for (;;) __asm__ volatile("wfi");
}

void Default_Handler() {
  for (;;) {
  }
}

// As a firmware does (hal/cortex_m/no_heap.cpp): a pure virtual call traps instead of reaching
// std::terminate, and static destructors are never registered (the firmware never exits).
void __cxa_pure_virtual() {
  for (;;) {
  }
}
int __cxa_atexit(void (*)(void*), void*, void*) {
  return 0;
}
void* __dso_handle = nullptr;

// newlib's malloc and free ask _sbrk for memory (only linked by fixtures that use the heap).
void* _sbrk(int increment) {
  alignas(8) static unsigned char heap[1024];
  static int used = 0;
  void* block = heap + used;
  used += increment;
  return block;
}
}
