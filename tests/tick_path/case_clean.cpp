// Clean: the tick calls a virtual method of float-only classes (an indirect call, so every
// address-taken function counts as reachable). Double appears only in code that the vector
// tables alone refer to (HardFault_Handler, ADC_IRQHandler, Reset_Handler -> fixture_init),
// which must not count.
#include <cmath>

namespace fixture {

struct Filter {
  virtual float step(float x) = 0;

 protected:
  ~Filter() = default;  // not virtual: no deleting destructor (operator delete) in the vtable
};

struct LowPass final : Filter {
  float alpha = 0.1f;
  float y = 0.0f;
  float step(float x) override { return y += alpha * (x - y); }
};

struct Deadband final : Filter {
  float step(float x) override { return std::fabs(x) < 0.01f ? 0.0f : x; }
};

struct Controller {
  float on_tick(float x);
};

LowPass g_low_pass;
Deadband g_deadband;
Filter* volatile g_filter = &g_low_pass;
Controller g_controller;
volatile float g_in;
volatile float g_out;
volatile double g_diagnostic;

__attribute__((noinline)) float Controller::on_tick(float x) {
  return 2.0f * g_filter->step(x);
}

}  // namespace fixture

using namespace fixture;

extern "C" void SysTick_Handler() {
  g_out = g_controller.on_tick(g_in);
}

extern "C" void PendSV_Handler() {
  g_out = std::sqrt(std::fabs(g_out)) + std::floor(g_in);
}

extern "C" void ADC_IRQHandler() {
  g_diagnostic = g_diagnostic + g_in;  // double, but only in an interrupt vector
}

extern "C" void HardFault_Handler() {
  g_diagnostic = static_cast<double>(g_in) * 1.5;  // double, but not on the tick path
  for (;;) {
  }
}

#ifdef FIXTURE_HOOK
// Control (case 1c): the handler's address also stored as a callback. Excluding the vector
// table must not hide that: the tick's virtual call may now reach HardFault_Handler.
void (*volatile g_fault_hook)();
#endif

extern "C" void fixture_init() {
  g_filter = g_in > 0.0f ? static_cast<Filter*>(&g_low_pass) : &g_deadband;
  g_diagnostic = std::sqrt(static_cast<double>(g_in));
#ifdef FIXTURE_HOOK
  g_fault_hook = HardFault_Handler;
#endif
}
