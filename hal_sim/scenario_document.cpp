// A scenario's document assembled from its files and flags, with the origin of every key
// (hal_sim/scenario_document.hpp).
#include "hal_sim/scenario_document.hpp"

#include <fmt/format.h>

#include <sstream>

#include "hal_sim/config_error.hpp"
#include "hal_sim/motor_file.hpp"

namespace imd::sim::detail {
namespace {

/// Parses VALUE as a TOML value; a bare word that is not TOML becomes a string.
toml::table parse_override_value(const std::string& text) {
  try {
    return toml::parse("value = " + text);
  } catch (const toml::parse_error&) {
    toml::table table;
    table.insert("value", text);
    return table;
  }
}

/// Applies one table.key=VALUE; its keys' origin becomes the flag that gave it, and so does
/// that of each table it creates (a --set nameplate.pole_pairs=2 adds [nameplate]).
void apply_override(ScenarioDocument& d, const ScenarioOverride& override_) {
  const std::string& assignment = override_.assignment;
  const std::string& flag = override_.flag;
  const auto equals = assignment.find('=');
  if (equals == std::string::npos || equals == 0) {
    throw ConfigError(fmt::format("{}: expected table.key=VALUE", flag));
  }
  const std::string path = assignment.substr(0, equals);
  const std::string text = assignment.substr(equals + 1);
  std::vector<std::string> parts;
  std::stringstream stream(path);
  for (std::string part; std::getline(stream, part, '.');) parts.push_back(part);
  if (parts.size() < 2) throw ConfigError(fmt::format("{}: expected table.key=VALUE", flag));
  // The motor table admits free keys, so an override there must name a contract key or one
  // the file has: a typo must not pass silently.
  if (parts[0] == "motor" && !kMotorKeys.count(parts[1]) && !d.doc.at_path(path)) {
    throw ConfigError(fmt::format("{}: unknown key {}", flag, path));
  }
  toml::table* table = &d.doc;
  std::string table_path;
  for (std::size_t i = 0; i + 1 < parts.size(); ++i) {
    table_path += (i == 0 ? "" : ".") + parts[i];
    toml::node* child = table->get(parts[i]);
    if (child == nullptr) {
      table->insert(parts[i], toml::table{});
      child = table->get(parts[i]);
      d.origins.set(table_path, flag);
    }
    table = child->as_table();
    if (table == nullptr) throw ConfigError(fmt::format("{}: {} is not a table", flag, parts[i]));
  }
  toml::table parsed = parse_override_value(text);
  table->insert_or_assign(parts.back(), std::move(*parsed.get("value")));
  d.origins.clear_below(path);  // an inline table replaces what was there
  d.origins.set(path, flag);
}

/// The path of the motor file `file` names: relative to the scenario's directory, also when a
/// --set gives it (docs/scenarios.md), which the message says when there is no such file.
std::filesystem::path motor_path_of(const std::filesystem::path& scenario, const toml::node& file,
                                    const std::string& key, const std::string& origin) {
  const auto* name = file.as_string();
  if (name == nullptr) throw ConfigError(fmt::format("{}: {} must be a string", origin, key));
  const std::filesystem::path path = scenario.parent_path() / name->get();
  std::error_code status;
  if (!std::filesystem::exists(path, status)) {
    const std::filesystem::path directory = scenario.parent_path();
    if (std::filesystem::path(name->get()).is_absolute()) {
      throw ConfigError(fmt::format("{}: {}: {}: cannot open file", origin, key, path.string()));
    }
    throw ConfigError(fmt::format(
        "{}: {}: {}: cannot open file (\"{}\" is taken relative to the scenario's directory, "
        "{})",
        origin, key, path.string(), name->get(), directory.empty() ? "." : directory.string()));
  }
  return path;
}

/// The [motor] table of the motor file at `motor_path`.
toml::table motor_table_of(const std::filesystem::path& motor_path) {
  const toml::table motor_doc = parse_toml_file(motor_path);
  const toml::node* motor = motor_doc.get("motor");
  if (motor == nullptr || !motor->is_table()) {
    throw ConfigError(fmt::format("{}: missing table [motor]", motor_path.string()));
  }
  return *motor->as_table();
}

/// The keys of [plant] that `base` supplies (those [plant] does not set) come from where
/// `base_origins` says base's table `base_table` got them; a missing one is base's to add.
void inherit_plant_origins(ScenarioDocument& d, const toml::table& base,
                           const KeyOrigins& base_origins, const std::string& base_table) {
  const toml::table* plant = d.doc["plant"].as_table();
  for (const auto& [key, value] : base) {
    const std::string name(key.str());
    if (plant == nullptr || plant->get(name) == nullptr) {
      d.origins.set("plant." + name, base_origins.of(base_table + "." + name));
    }
  }
  d.origins.set("plant", base_origins.of(base_table));
}

}  // namespace

ScenarioDocument assemble_scenario(const std::filesystem::path& path,
                                   const std::vector<ScenarioOverride>& overrides,
                                   const std::optional<std::filesystem::path>& model_file) {
  const std::string source = path.string();
  ScenarioDocument d{parse_toml_file(path), KeyOrigins(source), std::nullopt};
  toml::table& doc = d.doc;
  if (const toml::node* motor_file = doc.get("motor_file")) {
    if (doc.get("motor") != nullptr) {
      throw ConfigError(fmt::format("{}: give either motor_file or [motor], not both", source));
    }
    const std::filesystem::path motor_path = motor_path_of(path, *motor_file, "motor_file", source);
    doc.insert("motor", motor_table_of(motor_path));
    doc.erase("motor_file");
    d.origins.set("motor", motor_path.string());
  }
  // The [plant] keys the scenario file sets are its own, whatever motor the plant starts from.
  if (const toml::table* plant = doc["plant"].as_table()) {
    for (const auto& [key, value] : *plant)
      d.origins.set("plant." + std::string(key.str()), source);
  }
  // model_file: the controller's motor from the file, the plant stays the scenario's motor;
  // before the overrides, so that motor.* changes the controller's and plant.* the plant's.
  std::optional<toml::table> scenario_motor;
  const KeyOrigins scenario_origins = d.origins;
  if (model_file) {
    if (doc.get("motor") != nullptr) scenario_motor = *doc.get("motor")->as_table();
    std::error_code status;
    if (!std::filesystem::exists(*model_file, status)) {
      throw ConfigError(
          fmt::format("{}: cannot open file (a relative path is taken from the "
                      "working directory, {})",
                      model_file->string(), std::filesystem::current_path(status).string()));
    }
    const toml::table model_doc = parse_toml_file(*model_file);
    (void)parse_motor_table(model_doc, model_file->string());  // its own errors, its own name
    doc.insert_or_assign("motor", *model_doc.get("motor")->as_table());
    d.origins.clear_below("motor");
    d.origins.set("motor", model_file->string());
  }
  for (const ScenarioOverride& override_ : overrides) apply_override(d, override_);
  // [plant] motor_file: the simulated motor starts from that file instead of [motor].
  d.plant_base = scenario_motor;
  toml::table* plant = doc["plant"].as_table();
  if (const toml::node* file = plant != nullptr ? plant->get("motor_file") : nullptr) {
    const std::filesystem::path motor_path =
        motor_path_of(path, *file, "plant.motor_file", d.origins.of("plant.motor_file"));
    d.plant_base = motor_table_of(motor_path);
    plant->erase("motor_file");
    inherit_plant_origins(d, *d.plant_base, KeyOrigins(motor_path.string()), "motor");
  } else if (d.plant_base) {
    inherit_plant_origins(d, *d.plant_base, scenario_origins, "motor");
  } else if (const toml::table* motor = doc["motor"].as_table(); plant != nullptr && motor) {
    inherit_plant_origins(d, *motor, KeyOrigins(d.origins), "motor");
  }
  // A commissioning run gives the drive no motor: without [motor], the plant's stands for it.
  if (doc.get("motor") == nullptr && d.plant_base && doc.get("nameplate") != nullptr) {
    doc.insert("motor", *d.plant_base);
    d.origins.set("motor", d.origins.of("plant"));
  }
  return d;
}

}  // namespace imd::sim::detail
