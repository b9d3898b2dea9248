// The tick allocates.
#include <cstddef>
#include <cstdlib>

namespace fixture {
volatile std::size_t g_size = 16;
void* volatile g_block;
}  // namespace fixture

extern "C" void SysTick_Handler() {
  fixture::g_block = std::malloc(fixture::g_size);
}
extern "C" void fixture_init() {}
