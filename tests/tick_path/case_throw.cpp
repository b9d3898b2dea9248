// With -fno-exceptions, std::array::at still calls std::__throw_out_of_range_fmt.
#include <array>
#include <cstddef>

namespace fixture {
std::array<float, 4> g_table{1.0f, 2.0f, 3.0f, 4.0f};
volatile std::size_t g_index;
volatile float g_out;
}  // namespace fixture

extern "C" void SysTick_Handler() {
  fixture::g_out = fixture::g_table.at(fixture::g_index);
}
extern "C" void fixture_init() {}
