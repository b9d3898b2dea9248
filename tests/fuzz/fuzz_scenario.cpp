// libFuzzer harness: arbitrary text as a scenario file, through load_scenario itself (the
// file is written to a temporary directory, as drive_sim would read it). The loader must return
// a scenario or throw ConfigError; any other exception, a crash, a hang or a sanitizer report
// is a bug. The directory holds a valid motor file, so that motor_file = "m.toml" reaches the
// rest of the loader.
#include <unistd.h>

#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <string>

#include "hal_sim/config_error.hpp"
#include "hal_sim/scenario.hpp"
#include "fuzz_check.hpp"

namespace {

std::filesystem::path directory() {
  static const std::filesystem::path dir = [] {
    const std::filesystem::path d = std::filesystem::temp_directory_path() /
                                    ("imd_fuzz_scenario." + std::to_string(::getpid()));
    std::filesystem::create_directories(d);
    std::ofstream(d / "m.toml") << "[motor]\nRs_Ohm = 14.0\nLs_H = 0.4\nLm_H = 0.377\n"
                                   "Rr_Ohm = 10.1\nLr_H = 0.4128\nJ_kgm2 = 0.01\n"
                                   "pole_pairs = 1\nfriction_Nms = 0.0\n";
    return d;
  }();
  return dir;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::filesystem::path file = directory() / "s.toml";
  {
    std::ofstream out(file, std::ios::binary | std::ios::trunc);
    out.write(reinterpret_cast<const char*>(data), static_cast<std::streamsize>(size));
  }
  try {
    const imd::sim::Scenario s = imd::sim::load_scenario(file);
    FUZZ_CHECK(s.sample_period_s >= 1e-6 && s.sample_period_s <= 1e-2);
  } catch (const imd::sim::ConfigError&) {
  }
  return 0;
}
