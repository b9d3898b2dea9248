#include "hal_sim/motor_file.hpp"

#include <algorithm>

#include <fmt/format.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <system_error>

#include "hal_sim/config_error.hpp"

namespace imd::sim {
namespace {

const char* type_name(const toml::node& node) {
  switch (node.type()) {
    case toml::node_type::string:
      return "a string";
    case toml::node_type::integer:
      return "an integer";
    case toml::node_type::floating_point:
      return "a number";
    case toml::node_type::boolean:
      return "a boolean";
    case toml::node_type::table:
      return "a table";
    case toml::node_type::array:
      return "an array";
    default:
      return "a date or time";
  }
}

/// Where a key is, for messages: the file (or flag) each key came from, and the table ("motor"
/// or "plant").
struct Place {
  const MotorKeyOrigin& origin_of;
  std::string_view table;
};

const toml::node& require_key(const toml::table& motor, std::string_view key, Place at) {
  const toml::node* node = motor.get(key);
  if (node == nullptr) {
    throw ConfigError(fmt::format("{}: missing key {}.{}", at.origin_of(key), at.table, key));
  }
  return *node;
}

double require_number(const toml::table& motor, std::string_view key, Place at) {
  const toml::node& node = require_key(motor, key, at);
  if (const auto* real = node.as_floating_point()) return real->get();
  if (const auto* integer = node.as_integer()) return static_cast<double>(integer->get());
  throw ConfigError(fmt::format("{}: {}.{} must be a number, got {}", at.origin_of(key), at.table,
                                key, type_name(node)));
}

int require_integer(const toml::table& motor, std::string_view key, Place at) {
  const toml::node& node = require_key(motor, key, at);
  if (const auto* integer = node.as_integer()) {
    const int64_t value = integer->get();
    if (value < 1 || value > control::kMaxPolePairs) {
      throw ConfigError(fmt::format("{}: {}.{} = {}: must be an integer in 1..{}",
                                    at.origin_of(key), at.table, key, value,
                                    control::kMaxPolePairs));
    }
    return static_cast<int>(value);
  }
  if (const auto* real = node.as_floating_point()) {  // 2.5 pole pairs; 2.0 too, as TOML types it
    std::string shown = fmt::format("{}", real->get());
    if (shown.find_first_of(".eEn") == std::string::npos) shown += ".0";
    throw ConfigError(fmt::format("{}: {}.{} = {}: must be an integer", at.origin_of(key),
                                  at.table, key, shown));
  }
  throw ConfigError(fmt::format("{}: {}.{} must be an integer, got {}", at.origin_of(key),
                                at.table, key, type_name(node)));
}

}  // namespace

toml::table parse_toml_file(const std::filesystem::path& path) {
  std::error_code status;
  if (std::filesystem::exists(path, status) && !std::filesystem::is_regular_file(path, status)) {
    throw ConfigError(fmt::format("{}: not a regular file", path.string()));
  }
  if (!std::ifstream(path).good()) {
    throw ConfigError(fmt::format("{}: cannot open file", path.string()));
  }
  try {
    return toml::parse_file(path.string());
  } catch (const toml::parse_error& error) {
    throw ConfigError(fmt::format("{}:{}:{}: TOML syntax error: {}", path.string(),
                                  error.source().begin.line, error.source().begin.column,
                                  error.description()));
  }
}

control::MotorParameters parse_motor_table(const toml::table& document, std::string_view source,
                                           std::string_view table) {
  return parse_motor_table(
      document, [source](std::string_view) { return std::string(source); }, table);
}

control::MotorParameters parse_motor_table(const toml::table& document,
                                           const MotorKeyOrigin& origin_of,
                                           std::string_view table) {
  const toml::node* motor_node = document.get(table);
  if (motor_node == nullptr) {
    throw ConfigError(fmt::format("{}: missing table [{}]", origin_of(""), table));
  }
  const toml::table* motor = motor_node->as_table();
  if (motor == nullptr) {
    throw ConfigError(fmt::format("{}: {} must be a table, got {}", origin_of(""), table,
                                  type_name(*motor_node)));
  }
  const Place at{origin_of, table};
  control::MotorParameters p;
  p.Rs_Ohm = require_number(*motor, "Rs_Ohm", at);
  p.Ls_H = require_number(*motor, "Ls_H", at);
  p.Lm_H = require_number(*motor, "Lm_H", at);
  p.Rr_Ohm = require_number(*motor, "Rr_Ohm", at);
  p.Lr_H = require_number(*motor, "Lr_H", at);
  p.J_kgm2 = require_number(*motor, "J_kgm2", at);
  p.pole_pairs = require_integer(*motor, "pole_pairs", at);
  p.friction_Nms = require_number(*motor, "friction_Nms", at);
  if (const auto problem = control::find_invalid_parameter(p)) {
    throw ConfigError(fmt::format("{}: {}.{} = {}: {}", origin_of(problem->key), table,
                                  problem->key, problem->value, problem->rule));
  }
  return p;
}

namespace {
/// A TOML float that reads back exactly: 17 significant digits, always with a '.' or an
/// exponent (TOML reads "0" as an integer).
std::string toml_float(double value) {
  std::string text = fmt::format("{:.17g}", value);
  if (text.find_first_of(".eEn") == std::string::npos) text += ".0";
  return text;
}
}  // namespace

std::string motor_file_text(const control::MotorParameters& m, std::string_view name,
                            std::string_view comment) {
  std::string text;
  for (std::size_t begin = 0; begin < comment.size();) {
    const std::size_t end = std::min(comment.find('\n', begin), comment.size());
    text += fmt::format("# {}\n", comment.substr(begin, end - begin));
    begin = end + 1;
  }
  // A TOML basic string: quotes and backslashes escaped, control characters left out.
  std::string quoted;
  for (const char c : name) {
    if (c == '"' || c == '\\') quoted += '\\';
    if (static_cast<unsigned char>(c) >= 0x20) quoted += c;
  }
  text += fmt::format("[motor]\nname = \"{}\"\n", quoted);
  text += fmt::format("Rs_Ohm = {}\nLs_H = {}\nLm_H = {}\nRr_Ohm = {}\n", toml_float(m.Rs_Ohm),
                      toml_float(m.Ls_H), toml_float(m.Lm_H), toml_float(m.Rr_Ohm));
  text += fmt::format("Lr_H = {}\nJ_kgm2 = {}\npole_pairs = {}\nfriction_Nms = {}\n",
                      toml_float(m.Lr_H), toml_float(m.J_kgm2), m.pole_pairs,
                      toml_float(m.friction_Nms));
  return text;
}

control::MotorParameters load_motor_file(const std::filesystem::path& path) {
  return parse_motor_table(parse_toml_file(path), path.string());
}

}  // namespace imd::sim
