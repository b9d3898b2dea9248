// Initialization uses double and std::sqrt(double); the tick is float only: clean.
#include <cmath>

namespace fixture {
volatile float g_in;
volatile float g_out;
volatile double g_gain_d;
float g_gain = 1.0f;
}  // namespace fixture

using namespace fixture;

extern "C" void fixture_init() {
  g_gain_d = std::sqrt(static_cast<double>(g_in) * 3.0) + 0.25;
  g_gain = static_cast<float>(g_gain_d);
}

extern "C" void SysTick_Handler() {
  g_out = g_in * g_gain;
}
