// libFuzzer harness: arbitrary text as a motor file (hal_sim/motor_file.hpp). The parser must
// either return a valid motor or throw ConfigError (the user's message); any other exception,
// a crash or a sanitizer report is a bug.
#include <cstddef>
#include <cstdint>
#include <string_view>

#include <toml++/toml.h>

#include "control/motor_parameters.hpp"
#include "hal_sim/config_error.hpp"
#include "hal_sim/motor_file.hpp"
#include "fuzz_check.hpp"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string_view text(reinterpret_cast<const char*>(data), size);
  toml::table document;
  try {
    document = toml::parse(text, std::string_view("fuzz.toml"));
  } catch (const toml::parse_error&) {
    return 0;  // load_motor_file turns this into a ConfigError (parse_toml_file)
  }
  try {
    const imd::control::MotorParameters m = imd::sim::parse_motor_table(document, "fuzz.toml");
    FUZZ_CHECK(!imd::control::find_invalid_parameter(m).has_value());
  } catch (const imd::sim::ConfigError&) {
  }
  return 0;
}
