// The stack check's fixture: frames of known size behind virtual calls of two interfaces whose
// methods share the vtable slot 0. The main thread reaches the 2 KiB frame; the interrupts reach
// only the small one, unless FIXTURE_HOOK adds a call through a function pointer, or
// FIXTURE_MIXED one in the same statement as a virtual call.
// FIXTURE_RECURSION and FIXTURE_VLA add a recursion and a dynamic frame to the main thread.
namespace fixture {

struct Light {
  virtual void light(int x) = 0;
};
struct Heavy {
  virtual void heavy(int x) = 0;
};
struct SmallWork final : Light {
  void light(int x) override;
};
struct BigWork final : Heavy {
  void heavy(int x) override;
};

__attribute__((noinline)) void SmallWork::light(int x) {
  volatile char buffer[64];
  buffer[x & 63] = 1;
}
__attribute__((noinline)) void BigWork::heavy(int x) {
  volatile char buffer[2048];
  buffer[x & 2047] = 1;
}

#ifdef FIXTURE_RECURSION
__attribute__((noinline)) int depth(int n) {
  volatile char buffer[16];
  buffer[0] = char(n);
  return n > 0 ? buffer[depth(n - 1) & 15] : 0;  // no tail call: GCC cannot make it a loop
}
#endif
#ifdef FIXTURE_VLA
__attribute__((noinline)) int sized(int n) {
  volatile char buffer[n];
  buffer[0] = 1;
  return buffer[0];
}
#endif

}  // namespace fixture

fixture::SmallWork g_small;
fixture::BigWork g_big;
fixture::Light* volatile g_light = &g_small;
fixture::Heavy* volatile g_heavy = &g_big;
void (*volatile g_hook)(int) = nullptr;

extern "C" void SysTick_Handler() {
  g_light->light(1);
}

extern "C" void PendSV_Handler() {
#ifdef FIXTURE_MIXED
  g_hook = nullptr;  // never called: what the check assumes is what the code could do
  if (g_hook != nullptr) g_hook((g_light->light(2), 2));
#else
  g_light->light(2);
#endif
#ifdef FIXTURE_HOOK
  if (g_hook != nullptr) g_hook(3);
#endif
}

extern "C" void fixture_init() {
  g_heavy->heavy(4);
#ifdef FIXTURE_RECURSION
  g_light->light(fixture::depth(5));
#endif
#ifdef FIXTURE_VLA
  g_light->light(fixture::sized(5));
#endif
}
