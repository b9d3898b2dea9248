// A virtual destructor puts the deleting destructor, and with it operator delete, into the
// vtable: a tick making any virtual call may reach it.
namespace fixture {

struct Sink {
  virtual ~Sink() = default;
  virtual void put(float x) = 0;
};

struct Dac final : Sink {
  void put(float x) override { out = x; }
  volatile float out = 0.0f;
};

Dac g_dac;
Sink* volatile g_sink = &g_dac;
volatile float g_in;

}  // namespace fixture

extern "C" void SysTick_Handler() {
  fixture::g_sink->put(fixture::g_in);
}
extern "C" void fixture_init() {}
