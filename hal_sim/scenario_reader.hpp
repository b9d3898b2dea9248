#pragma once
/// The scenario loader's reader (internal to hal_sim/scenario*.cpp): typed, validated access to
/// the keys of a TOML document by dotted path, with messages that name the file or flag the key
/// came from, the key and the value, and a final check that every key of the document was read.
#include <fmt/format.h>
#include <toml++/toml.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <initializer_list>
#include <limits>
#include <optional>
#include <set>
#include <sstream>
#include <string>
#include <span>
#include <string_view>
#include <vector>

#include "hal_sim/config_error.hpp"
#include "hal_sim/scenario_origins.hpp"

namespace imd::sim {
struct Scenario;
}  // namespace imd::sim

namespace imd::sim::detail {

/// Reads keys by dotted path and remembers which it read, so that anything else in the
/// document can be reported as unknown.
class Reader {
 public:
  /// `origins` must outlive the reader.
  Reader(const toml::table& doc, const KeyOrigins& origins) : doc_(doc), origins_(origins) {}

  [[noreturn]] void fail(std::string_view path, const std::string& what) const {
    throw ConfigError(fmt::format("{}: {}: {}", origins_.of(path), path, what));
  }
  /// Fails at `path` for a rule it shares with `other`. When `other`'s value came from another
  /// place (another file, a command-line flag), the message names that place too and how to
  /// change either: "FILE: metrics.settle_s: = 0.5: must be below simulation.duration_s (0.3);
  /// simulation.duration_s comes from --duration-s 0.3: change it there, or --set
  /// metrics.settle_s=VALUE".
  [[noreturn]] void fail_with(std::string_view path, std::string_view other,
                              const std::string& what) const {
    const std::string& here = origins_.of(path);
    const std::string& there = origins_.of(other);
    if (here == there) fail(path, what);
    if (from_command_line(path)) {
      fail(path, fmt::format("{}; {} comes from {}", what, other, there));
    }
    fail(path, fmt::format("{}; {} comes from {}: change it there, or --set {}=VALUE", what, other,
                           there, path));
  }
  /// Whether the key's value came from a command-line flag (--set, --duration-s), not a file.
  bool from_command_line(std::string_view path) const {
    return origins_.of(path).rfind("--", 0) == 0;
  }

  /// Whether the document has the key (without marking it read).
  bool present(std::string_view path) const { return doc_.at_path(path).node() != nullptr; }

  const toml::node* find(std::string_view path) {
    read_.insert(std::string(path));
    return doc_.at_path(path).node();
  }

  /// A finite number (or the fallback, which may be infinite, when the key is absent).
  double number(std::string_view path, std::optional<double> fallback) {
    const toml::node* node = find(path);
    if (node == nullptr) {
      if (!fallback) fail(path, "missing key");
      return *fallback;
    }
    double value = 0.0;
    if (const auto* real = node->as_floating_point()) {
      value = real->get();
    } else if (const auto* integer = node->as_integer()) {
      value = static_cast<double>(integer->get());
    } else {
      fail(path, "must be a number");
    }
    if (!std::isfinite(value)) fail(path, fmt::format("= {}: must be finite", value));
    return value;
  }
  double positive(std::string_view path, std::optional<double> fallback) {
    const double value = number(path, fallback);
    if (!(value > 0.0)) fail(path, fmt::format("= {}: must be > 0", value));
    return value;
  }
  /// A positive number, or inf for "no limit" (also when the key is absent).
  double positive_or_inf(std::string_view path) {
    constexpr double kInf = std::numeric_limits<double>::infinity();
    const toml::node* node = find(path);
    if (node == nullptr) return kInf;
    const std::optional<double> value = node->is_number() ? node->value<double>() : std::nullopt;
    if (!value || !(*value > 0.0) || std::isnan(*value)) {
      fail(path, fmt::format("= {}: must be a number > 0, or inf for no limit", text(*node)));
    }
    return *value;
  }
  double non_negative(std::string_view path, std::optional<double> fallback) {
    const double value = number(path, fallback);
    if (!(value >= 0.0)) fail(path, fmt::format("= {}: must be >= 0", value));
    return value;
  }
  int64_t integer(std::string_view path, int64_t fallback, int64_t low, int64_t high) {
    const toml::node* node = find(path);
    if (node == nullptr) return fallback;
    const auto* value = node->as_integer();
    if (value == nullptr && node->is_floating_point()) {  // 2.5; 2.0 too, as TOML types it
      fail(path, fmt::format("= {}: must be an integer", text(*node)));
    }
    if (value == nullptr) fail(path, "must be an integer");
    if (value->get() < low || value->get() > high) {
      fail(path, fmt::format("= {}: must be in {}..{}", value->get(), low, high));
    }
    return value->get();
  }
  bool boolean(std::string_view path, bool fallback) {
    const toml::node* node = find(path);
    if (node == nullptr) return fallback;
    const auto* value = node->as_boolean();
    if (value == nullptr) fail(path, "must be true or false");
    return value->get();
  }
  std::string choice(std::string_view path, std::string fallback,
                     std::initializer_list<std::string_view> allowed) {
    return choice(path, std::move(fallback), std::span<const std::string_view>(allowed));
  }
  std::string choice(std::string_view path, std::string fallback,
                     std::span<const std::string_view> allowed) {
    const toml::node* node = find(path);
    if (node == nullptr) return fallback;
    const auto* value = node->as_string();
    std::string list;
    for (auto option : allowed) list += fmt::format("{}\"{}\"", list.empty() ? "" : ", ", option);
    if (value == nullptr) fail(path, "must be one of " + list);
    for (auto option : allowed) {
      if (value->get() == option) return value->get();
    }
    fail(path, fmt::format("= \"{}\": must be one of {}", value->get(), list));
  }
  std::vector<double> numbers(std::string_view path) {
    const toml::node* node = find(path);
    if (node == nullptr) fail(path, "missing key");
    const auto* array = node->as_array();
    if (array == nullptr) fail(path, "must be an array of numbers");
    std::vector<double> values;
    for (const toml::node& element : *array) {
      if (const auto* real = element.as_floating_point()) {
        values.push_back(real->get());
      } else if (const auto* integer = element.as_integer()) {
        values.push_back(static_cast<double>(integer->get()));
      } else {
        fail(path, "must be an array of numbers");
      }
    }
    return values;
  }
  /// Absent: nullopt; present: a finite number > 0.
  std::optional<double> optional_positive(std::string_view path) {
    if (!present(path)) return std::nullopt;
    return positive(path, std::nullopt);
  }
  /// Absent: nullopt; present: an integer in low..high.
  std::optional<int64_t> optional_integer(std::string_view path, int64_t low, int64_t high) {
    if (!present(path)) return std::nullopt;
    return integer(path, low, low, high);
  }
  /// An array of tables ([[path]] in the file; may be empty), or nullptr when absent. The keys of
  /// its tables are not checked by reject_unknown(): the caller checks them (check_keys).
  const toml::array* table_array(std::string_view path) {
    accept_table(path);
    const toml::node* node = doc_.at_path(path).node();
    if (node == nullptr) return nullptr;
    const auto* array = node->as_array();
    if (array == nullptr || (!array->empty() && !array->is_array_of_tables())) {
      fail(path, fmt::format("must be an array of tables ([[{}]])", path));
    }
    return array;
  }
  /// Throws on a key of `table` (at `prefix`) that is not in `known`.
  void check_keys(const std::string& prefix, const toml::table& table,
                  std::initializer_list<std::string_view> known) const {
    for (const auto& [key, node] : table) {
      if (std::find(known.begin(), known.end(), key.str()) == known.end()) {
        unknown_key(prefix + "." + std::string(key.str()));
      }
    }
  }
  [[noreturn]] void unknown_key(std::string_view path) const {
    throw ConfigError(fmt::format("{}: unknown key {}", origins_.of(path), path));
  }
  /// A value as TOML writes it (strings in double quotes), for messages.
  static std::string text(const toml::node& node) {
    if (const auto* string = node.as_string()) return fmt::format("\"{}\"", string->get());
    std::ostringstream out;
    node.visit([&](const auto& value) { out << value; });
    return out.str();
  }

  /// Marks a whole table as read (its keys are checked elsewhere).
  void accept_table(std::string_view path) { accepted_.insert(std::string(path)); }

  /// Throws on the first key that nothing read.
  void reject_unknown() const { walk(doc_, ""); }

 private:
  void walk(const toml::table& table, const std::string& prefix) const {
    for (const auto& [key, node] : table) {
      const std::string path =
          prefix.empty() ? std::string(key.str()) : prefix + "." + std::string(key.str());
      if (accepted_.count(path)) continue;
      if (const auto* child = node.as_table()) {
        walk(*child, path);
      } else if (!read_.count(path)) {
        unknown_key(path);
      }
    }
  }

  const toml::table& doc_;
  const KeyOrigins& origins_;
  std::set<std::string> read_, accepted_;
};

// The sections read in scenario_events.cpp.
void read_faults(Reader& r, Scenario& s);        ///< [[faults]] (after inverter.v_bus_V)
void read_can_commands(Reader& r, Scenario& s);  ///< [[can_commands]]
void read_can(Reader& r, Scenario& s);           ///< [can]
void read_protection(Reader& r, Scenario& s);    ///< [protection] (after inverter.v_bus_V)
/// [nameplate], [identify]: appends the nameplate writes and the identify command to
/// s.can_commands.
void read_commissioning(Reader& r, Scenario& s);

}  // namespace imd::sim::detail
