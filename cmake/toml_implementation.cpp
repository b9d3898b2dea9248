// toml++'s implementation, compiled once for a static build (cmake/LinuxDependencies.cmake):
// every other file includes toml++ with TOML_HEADER_ONLY=0, its declarations only.
#define TOML_IMPLEMENTATION
#include <toml++/toml.h>
