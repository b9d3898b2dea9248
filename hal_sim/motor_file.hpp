#pragma once
/// Loading of the [motor] table from TOML (a motor file or a scenario file), with validation.
///
///   [motor]
///   Rs_Ohm = 14.0        Ls_H = 0.4       Lm_H = 0.377     Rr_Ohm = 10.1
///   Lr_H = 0.4128        J_kgm2 = 0.01    pole_pairs = 1   friction_Nms = 0.0
///
/// All eight keys are required; other keys in the table are free (names, ratings). Host only.
#include <toml++/toml.h>
#include <filesystem>
#include <functional>
#include <string>
#include <string_view>

#include "control/motor_parameters.hpp"

namespace imd::sim {

/// Reads and validates the [motor] table of a TOML file. Throws ConfigError naming the file,
/// the key and the value on a syntax error, a missing key, a wrong type or an invalid value.
control::MotorParameters load_motor_file(const std::filesystem::path& path);

/// Reads and validates the [motor] table (or another of the same keys, such as a scenario's
/// completed [plant]) of an already parsed document. `source` names the document in error
/// messages.
control::MotorParameters parse_motor_table(const toml::table& document, std::string_view source,
                                           std::string_view table = "motor");

/// Names, for messages, the file or flag a key of the table came from ("" for the table
/// itself): a scenario's [motor] may come from a motor file, its keys from --set overrides.
using MotorKeyOrigin = std::function<std::string(std::string_view key)>;

/// parse_motor_table, each message naming the origin of the key it is about.
control::MotorParameters parse_motor_table(const toml::table& document,
                                           const MotorKeyOrigin& origin_of,
                                           std::string_view table = "motor");

/// The text of a motor file that load_motor_file reads back exactly (every value to 17
/// significant digits): a comment block (each line of `comment` gets "# "), then [motor] with
/// `name` and the eight keys.
std::string motor_file_text(const control::MotorParameters& motor, std::string_view name,
                            std::string_view comment);

/// Parses a TOML file, turning a syntax error into a ConfigError with file, line and column.
toml::table parse_toml_file(const std::filesystem::path& path);

}  // namespace imd::sim
