#include "firmware/cortex_m/pil/pil_options.hpp"

#include <algorithm>

#include "firmware/laws/law_registry.hpp"

namespace imd::firmware {
namespace {

/// A count of milliseconds, 0..10^7; -1 if the word is not one.
long milliseconds(std::string_view word) noexcept {
  long value = 0;
  for (const char c : word) {
    if (c < '0' || c > '9' || value > 10'000'000) return -1;
    value = value * 10 + (c - '0');
  }
  return word.empty() || value > 10'000'000 ? -1 : value;
}

}  // namespace

PilOptions parse_pil_options(std::string_view command_line,
                             std::span<const sim::EmbeddedScenario* const> scenarios) noexcept {
  PilOptions o;
  o.scenario = scenarios.front();
  bool law_given = false;
  ControllerKind law = ControllerKind::dsmc;
  // remove_prefix and pointer-and-length views only: substr may throw, which a bare-metal
  // image without exceptions would link as abort().
  std::string_view rest = command_line;
  while (!rest.empty()) {
    const std::size_t end = std::min(rest.find(' '), rest.size());
    std::string_view word(rest.data(), end);
    rest.remove_prefix(std::min(end + 1, rest.size()));
    if (word.starts_with("scenario=")) {
      word.remove_prefix(9);
      const std::string_view name = word;
      o.scenario = nullptr;
      for (const sim::EmbeddedScenario* s : scenarios) {
        if (name == s->name) o.scenario = s;
      }
      if (o.scenario == nullptr) {
        o.error = "unknown scenario";
        return o;
      }
    } else if (word.starts_with("controller=")) {
      word.remove_prefix(11);
      if (!controller_named(word, law)) {
        o.error = "unknown controller";
        return o;
      }
      law_given = true;
    } else if (word.starts_with("plant_rr_percent=")) {
      word.remove_prefix(17);
      int percent = 0;
      for (const char c : word) {
        percent = c >= '0' && c <= '9' && percent < 1000 ? percent * 10 + (c - '0') : 100000;
      }
      if (word.empty() || percent < 10 || percent > 500) {
        o.error = "plant_rr_percent must be 10..500";
        return o;
      }
      o.plant_rr_percent = percent;
    } else if (word.starts_with("stall_at_ms=") || word.starts_with("duration_ms=")) {
      const bool stall = word.starts_with("stall_at_ms=");
      word.remove_prefix(12);
      const long ms = milliseconds(word);
      if (ms < 0 || (!stall && ms == 0)) {
        o.error = "stall_at_ms and duration_ms must be whole milliseconds (duration > 0)";
        return o;
      }
      (stall ? o.stall_at_ms : o.duration_ms) = ms;
    }
  }
  o.drive = o.scenario->drive;
  if (law_given) o.drive.controller = law;
  return o;
}

}  // namespace imd::firmware
