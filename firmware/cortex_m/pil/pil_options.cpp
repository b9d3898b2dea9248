#include "firmware/cortex_m/pil/pil_options.hpp"

#include <algorithm>

#include "firmware/laws/law_registry.hpp"

namespace imd::firmware {

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
    }
  }
  o.drive = o.scenario->drive;
  if (law_given) o.drive.controller = law;
  return o;
}

}  // namespace imd::firmware
