// Double arithmetic reached only through a virtual call: found through the vtable.
namespace fixture {

struct Model {
  virtual float eval(float x) = 0;

 protected:
  ~Model() = default;
};

struct FastModel final : Model {
  float eval(float x) override { return 0.5f * x; }
};

struct PreciseModel final : Model {
  float eval(float x) override { return static_cast<float>(static_cast<double>(x) * 0.1); }
};

FastModel g_fast;
PreciseModel g_precise;
Model* volatile g_model = &g_fast;
volatile float g_in;
volatile float g_out;

}  // namespace fixture

using namespace fixture;

extern "C" void SysTick_Handler() {
  g_out = g_model->eval(g_in);
}
extern "C" void fixture_init() {
  if (g_in < 0.0f) g_model = &g_precise;
}
