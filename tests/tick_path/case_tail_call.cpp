// The tick's last action is a call, compiled as a tail call (b.w publish): still an edge.
namespace fixture {
volatile float g_in;
volatile double g_published;

__attribute__((noinline)) void publish(float x) {
  g_published = x * 0.001;
}
}  // namespace fixture

extern "C" void SysTick_Handler() {
  fixture::publish(fixture::g_in);
}
extern "C" void fixture_init() {}
