// The tick calls a function that does double arithmetic: soft-float calls (__aeabi_f2d, ...).
namespace fixture {
volatile float g_in;
volatile float g_out;

__attribute__((noinline)) float scale(float x) {
  return static_cast<float>(x * 1.0000001);
}
}  // namespace fixture

extern "C" void SysTick_Handler() {
  fixture::g_out = fixture::scale(fixture::g_in) + 1.0f;
}
extern "C" void fixture_init() {}
