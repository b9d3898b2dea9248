#pragma once
/// A scenario's document as the loader reads it (internal to hal_sim/scenario*.cpp): the
/// scenario file with the motor files it names inlined, the --motor-file and the --set
/// overrides applied, and where each of its keys came from, so that a message names the file
/// or flag to fix.
#include <toml++/toml.h>

#include <filesystem>
#include <optional>
#include <set>
#include <string>
#include <vector>

#include "hal_sim/scenario.hpp"
#include "hal_sim/scenario_origins.hpp"

namespace imd::sim::detail {

/// The keys of the motor contract (hal_sim/motor_file.hpp): [motor] admits other, free keys.
inline const std::set<std::string> kMotorKeys = {"Rs_Ohm", "Ls_H",   "Lm_H",       "Rr_Ohm",
                                                 "Lr_H",   "J_kgm2", "pole_pairs", "friction_Nms"};

struct ScenarioDocument {
  toml::table doc;
  KeyOrigins origins;
  /// The simulated motor when it is not [motor]: plant.motor_file's, or under a --motor-file
  /// the scenario's own motor. [plant]'s motor keys change it.
  std::optional<toml::table> plant_base;
};

/// Reads the scenario file at `path`, inlines `motor_file` and `plant.motor_file` (relative to
/// the scenario's directory), puts `model_file`'s [motor] in place of the scenario's (the
/// plant keeps the scenario's) and applies the `overrides` (table.key=VALUE) in order. Throws
/// ConfigError naming the file or the flag at fault.
ScenarioDocument assemble_scenario(const std::filesystem::path& path,
                                   const std::vector<ScenarioOverride>& overrides,
                                   const std::optional<std::filesystem::path>& model_file);

}  // namespace imd::sim::detail
