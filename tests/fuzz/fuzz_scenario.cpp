// libFuzzer harness: arbitrary text as a scenario file, through load_scenario itself (the
// file is written to a temporary directory, as drive_sim would read it). The loader must return
// a scenario within its limits or throw ConfigError; any other exception, a crash, a hang or a
// sanitizer report is a bug. The directory mirrors the repository's layout: the scenario in
// scenarios/, the shipped motor files in motors/, so that the shipped scenarios, the seeds,
// find their motor_file = "../motors/..." and reach the rest of the loader.
#include <unistd.h>

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <string>

#include "control/motor_parameters.hpp"
#include "hal_sim/config_error.hpp"
#include "hal_sim/scenario.hpp"
#include "fuzz_check.hpp"

namespace {

namespace fs = std::filesystem;

fs::path scenario_file() {
  static const fs::path file = [] {
    const fs::path dir = fs::temp_directory_path() / ("imd_fuzz_scenario." + std::to_string(::getpid()));
    fs::create_directories(dir / "scenarios");
    fs::create_directories(dir / "motors");
    for (const char* source : {IMD_SOURCE_DIR "/hal_sim/motors", IMD_SOURCE_DIR "/tests/data/motors"}) {
      for (const fs::directory_entry& e : fs::directory_iterator(source)) {
        fs::copy_file(e.path(), dir / "motors" / e.path().filename(),
                      fs::copy_options::overwrite_existing);
      }
    }
    return dir / "scenarios" / "s.toml";
  }();
  return file;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const fs::path file = scenario_file();
  {
    std::ofstream out(file, std::ios::binary | std::ios::trunc);
    out.write(reinterpret_cast<const char*>(data), static_cast<std::streamsize>(size));
  }
  try {
    const imd::sim::Scenario s = imd::sim::load_scenario(file);
    FUZZ_CHECK(s.sample_period_s >= 1e-6 && s.sample_period_s <= 1e-2);
    FUZZ_CHECK(!imd::control::find_invalid_parameter(s.motor).has_value());
    FUZZ_CHECK(!imd::control::find_invalid_parameter(s.plant).has_value());
    FUZZ_CHECK(s.duration_s > 0.0 && std::isfinite(s.duration_s));
    FUZZ_CHECK(s.v_bus_V > 0.0 && std::isfinite(s.v_bus_V));
    FUZZ_CHECK(s.i_max_A > 0.0);
    FUZZ_CHECK(s.substeps >= 1);
  } catch (const imd::sim::ConfigError&) {
  }
  return 0;
}
