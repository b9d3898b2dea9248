#pragma once
/// Error raised while loading a motor, scenario or board file. The message names the file, the
/// key and the offending value. Host only: never thrown in tick context.
#include <stdexcept>

namespace imd::sim {

class ConfigError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

}  // namespace imd::sim
