// The scenario sections about a run's events and the drive's supervision: [[faults]],
// [[can_commands]], [can] and [protection] (docs/scenarios.md).
#include <fmt/format.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <string>

#include "hal_sim/scenario.hpp"
#include "hal_sim/scenario_reader.hpp"

namespace imd::sim::detail {
namespace {

/// A key a fault may have besides at_s and kind, and the (one or two) kinds it belongs to.
struct FaultKey {
  std::string_view name;
  FaultKind kind, other_kind;
  std::string_view kinds_text;
};

constexpr std::array<FaultKey, 4> kFaultKeys{{
    {"surge_A", FaultKind::overcurrent, FaultKind::overcurrent, "overcurrent"},
    {"phase", FaultKind::overcurrent, FaultKind::phase_loss, "overcurrent and phase_loss"},
    {"bus_V", FaultKind::overvoltage, FaultKind::undervoltage, "overvoltage and undervoltage"},
    {"stall_us", FaultKind::overrun, FaultKind::overrun, "overrun"},
}};

FaultKind read_fault_kind(Reader& r, const std::string& path) {
  const toml::node* node = r.find(path);
  if (node == nullptr) r.fail(path, "missing key");
  const auto* name = node->as_string();
  if (const auto kind = name != nullptr ? parse_fault_kind(name->get()) : std::nullopt) {
    return *kind;
  }
  std::string list;
  for (int k = 0; k < kFaultKindCount; ++k) {
    list += fmt::format("{}\"{}\"", k == 0 ? "" : ", ", fault_kind_name(static_cast<FaultKind>(k)));
  }
  r.fail(path, fmt::format("= {}: must be one of {}", Reader::text(*node), list));
}

FaultInjection read_fault(Reader& r, const std::string& base, const toml::table& table,
                          double nominal_bus_V) {
  const auto key = [&](std::string_view name) { return fmt::format("{}.{}", base, name); };
  FaultInjection fault;
  fault.at_s = r.non_negative(key("at_s"), std::nullopt);
  fault.kind = read_fault_kind(r, key("kind"));
  fault.until_s = r.number(key("until_s"), fault.until_s);
  if (!(fault.until_s > fault.at_s)) {
    r.fail(key("until_s"), fmt::format("= {}: must be after at_s ({})", fault.until_s, fault.at_s));
  }
  const char* kind_name = fault_kind_name(fault.kind);

  for (const auto& [name, node] : table) {
    if (name == "at_s" || name == "kind" || name == "until_s") continue;
    const std::string_view key_name = name.str();  // clang 14 cannot capture a structured binding
    const auto known = std::find_if(kFaultKeys.begin(), kFaultKeys.end(),
                                    [&](const FaultKey& k) { return k.name == key_name; });
    if (known == kFaultKeys.end()) r.unknown_key(key(name.str()));
    if (known->kind != fault.kind && known->other_kind != fault.kind) {
      r.fail(key(name.str()), fmt::format("= {}: not a key of kind \"{}\" (only of {})",
                                          Reader::text(node), kind_name, known->kinds_text));
    }
  }
  switch (fault.kind) {
    case FaultKind::overcurrent:
      fault.surge_A = r.positive(key("surge_A"), std::nullopt);
      fault.phase = static_cast<int>(r.integer(key("phase"), 0, 0, 2));
      break;
    case FaultKind::phase_loss:
      fault.phase = static_cast<int>(r.integer(key("phase"), 0, 0, 2));
      break;
    case FaultKind::overvoltage:
    case FaultKind::undervoltage: {
      fault.bus_V = r.positive(key("bus_V"), std::nullopt);
      // The kind says which way the bus moves from inverter.v_bus_V.
      const bool over = fault.kind == FaultKind::overvoltage;
      if (over ? !(fault.bus_V > nominal_bus_V) : !(fault.bus_V < nominal_bus_V)) {
        r.fail_with(key("bus_V"), "inverter.v_bus_V",
                    fmt::format("= {}: must be {} inverter.v_bus_V ({} V) for {}", fault.bus_V,
                                over ? "above" : "below", nominal_bus_V, kind_name));
      }
      break;
    }
    case FaultKind::overrun:
      fault.stall_us = r.positive(key("stall_us"), 1000.0);
      if (!(fault.stall_us < 1e9)) {
        r.fail(key("stall_us"), fmt::format("= {}: must be below 1e9 us", fault.stall_us));
      }
      break;
    default:
      break;
  }
  // The board refuses what it cannot apply; the checks above name the key first.
  if (const char* error = fault_parameter_error(fault)) r.fail(base, error);
  return fault;
}

CanCommandScript read_can_command(Reader& r, int index, const toml::table& table) {
  const std::string base = fmt::format("can_commands[{}]", index);
  const auto key = [&](std::string_view name) { return fmt::format("{}.{}", base, name); };
  r.check_keys(
      base, table,
      {"at_s", "message", "fields", "every_s", "until_s", "counter", "corrupt_crc", "length"});
  CanCommandScript command;
  command.index = index;
  command.at_s = r.non_negative(key("at_s"), std::nullopt);

  const toml::node* message = r.find(key("message"));
  if (message == nullptr) r.fail(key("message"), "missing key");
  if (!message->is_string()) {
    r.fail(key("message"), fmt::format("= {}: must be a string", Reader::text(*message)));
  }
  command.message = message->as_string()->get();
  if (command.message.empty()) r.fail(key("message"), "= \"\": must name a message");

  if (const toml::node* fields = r.find(key("fields"))) {
    const auto* table_of_fields = fields->as_table();
    if (table_of_fields == nullptr) {
      r.fail(key("fields"), fmt::format("= {}: must be a table of name = number (e.g. "
                                        "{{ speed_ref_rad_s = 100 }})",
                                        Reader::text(*fields)));
    }
    for (const auto& [name, value] : *table_of_fields) {
      // Read from the node: a quoted field name may hold characters a dotted path cannot.
      const std::string path = fmt::format("{}.{}", key("fields"), name.str());
      const std::optional<double> number = value.is_number() ? value.value<double>() : std::nullopt;
      if (!number) r.fail(path, fmt::format("= {}: must be a number", Reader::text(value)));
      if (!std::isfinite(*number)) r.fail(path, fmt::format("= {}: must be finite", *number));
      command.fields.emplace_back(std::string(name.str()), *number);
    }
  }

  if (r.find(key("every_s")) != nullptr) command.every_s = r.positive(key("every_s"), 0.0);
  if (r.find(key("until_s")) != nullptr) {
    command.until_s = r.number(key("until_s"), std::nullopt);
    if (command.every_s == 0.0) {
      r.fail(key("until_s"), fmt::format("= {}: ends a repeat, needs every_s", command.until_s));
    }
    if (!(command.until_s >= command.at_s)) {
      r.fail(key("until_s"),
             fmt::format("= {}: must be >= at_s ({})", command.until_s, command.at_s));
    }
  }
  if (const auto counter = r.optional_integer(key("counter"), 0, 15)) {
    command.counter = static_cast<int>(*counter);
  }
  command.corrupt_crc = r.boolean(key("corrupt_crc"), false);
  if (const auto length = r.optional_integer(key("length"), 0, 8)) {
    command.length = static_cast<int>(*length);
  }
  return command;
}

}  // namespace

void read_faults(Reader& r, Scenario& s) {
  const toml::array* faults = r.table_array("faults");
  if (faults == nullptr) return;
  for (std::size_t i = 0; i < faults->size(); ++i) {
    s.faults.push_back(
        read_fault(r, fmt::format("faults[{}]", i), *faults->get(i)->as_table(), s.v_bus_V));
  }
  std::stable_sort(
      s.faults.begin(), s.faults.end(),
      [](const FaultInjection& a, const FaultInjection& b) { return a.at_s < b.at_s; });
}

void read_can_commands(Reader& r, Scenario& s) {
  const toml::array* commands = r.table_array("can_commands");
  if (commands == nullptr) return;
  for (std::size_t i = 0; i < commands->size(); ++i) {
    s.can_commands.push_back(
        read_can_command(r, static_cast<int>(i), *commands->get(i)->as_table()));
  }
}

void read_can(Reader& r, Scenario& s) {
  s.can_node_id = static_cast<int>(r.integer("can.node_id", 1, 0, 63));
  // Whole hertz, as the drive holds it (firmware DriveConfig, the set_telemetry_rate command).
  s.telemetry_rate_Hz = static_cast<int>(r.integer("can.telemetry_rate_Hz", 100, 10, 1000));
}

void read_protection(Reader& r, Scenario& s) {
  ProtectionSettings& p = s.protection;
  p.overcurrent_A = r.optional_positive("protection.overcurrent_A");
  p.bus_min_V = r.optional_positive("protection.bus_min_V");
  p.bus_max_V = r.optional_positive("protection.bus_max_V");
  if (p.bus_min_V && p.bus_max_V && !(*p.bus_max_V > *p.bus_min_V)) {
    r.fail_with(
        "protection.bus_max_V", "protection.bus_min_V",
        fmt::format("= {}: must be above protection.bus_min_V ({})", *p.bus_max_V, *p.bus_min_V));
  }
  // A limit on the wrong side of the nominal bus trips the drive as soon as it runs.
  if (p.bus_max_V && !(*p.bus_max_V > s.v_bus_V)) {
    r.fail_with("protection.bus_max_V", "inverter.v_bus_V",
                fmt::format("= {}: must be above inverter.v_bus_V ({} V), or the drive trips at "
                            "once",
                            *p.bus_max_V, s.v_bus_V));
  }
  if (p.bus_min_V && !(*p.bus_min_V < s.v_bus_V)) {
    r.fail_with("protection.bus_min_V", "inverter.v_bus_V",
                fmt::format("= {}: must be below inverter.v_bus_V ({} V), or the drive trips at "
                            "once",
                            *p.bus_min_V, s.v_bus_V));
  }
  p.overspeed_rad_s = r.optional_positive("protection.overspeed_rad_s");
  p.encoder_missing_counts = r.optional_positive("protection.encoder_missing_counts");
  p.encoder_max_load_share = r.optional_positive("protection.encoder_max_load_share");
  if (p.encoder_max_load_share && !(*p.encoder_max_load_share < 1.0)) {
    r.fail("protection.encoder_max_load_share",
           fmt::format("= {}: must be in (0, 1)", *p.encoder_max_load_share));
  }
  constexpr int64_t kIntMax = std::numeric_limits<int>::max();
  if (const auto ticks = r.optional_integer("protection.adc_stuck_ticks", 2, kIntMax)) {
    p.adc_stuck_ticks = static_cast<int>(*ticks);
  }
  p.inverter_voltage_error_share = r.optional_positive("protection.inverter_voltage_error_share");
  if (p.inverter_voltage_error_share && !(*p.inverter_voltage_error_share < 1.0)) {
    r.fail("protection.inverter_voltage_error_share",
           fmt::format("= {}: must be in (0, 1)", *p.inverter_voltage_error_share));
  }
  p.adc_noise_codes = r.optional_positive("protection.adc_noise_codes");
  p.command_timeout_s = r.optional_positive("protection.command_timeout_s");
  p.tick_budget_us = r.optional_positive("protection.tick_budget_us");
  p.stop_decel_rad_s2 = r.optional_positive("protection.stop_decel_rad_s2");
  p.command_timeout_stop = r.choice("protection.command_timeout_stop", "ss1", {"sto", "ss1"});
  p.emergency_stop_stop = r.choice("protection.emergency_stop_stop", "sto", {"sto", "ss1"});
  p.encoder_stop = r.choice("protection.encoder_stop", "dc_brake", {"sto", "dc_brake"});
  p.dc_brake_current_share = r.optional_positive("protection.dc_brake_current_share");
  if (p.dc_brake_current_share && !(*p.dc_brake_current_share <= 1.0)) {
    r.fail("protection.dc_brake_current_share",
           fmt::format("= {}: must be in (0, 1]", *p.dc_brake_current_share));
  }
}

}  // namespace imd::sim::detail
