#include "hal_sim/fault_injection.hpp"

#include <array>
#include <utility>

namespace imd::sim {
namespace {

constexpr std::array<std::pair<FaultKind, const char*>, kFaultKindCount> kNames{{
    {FaultKind::overcurrent, "overcurrent"},
    {FaultKind::overvoltage, "overvoltage"},
    {FaultKind::undervoltage, "undervoltage"},
    {FaultKind::encoder_loss, "encoder_loss"},
    {FaultKind::adc_stuck, "adc_stuck"},
    {FaultKind::phase_loss, "phase_loss"},
    {FaultKind::overrun, "overrun"},
    {FaultKind::can_silence, "can_silence"},
}};

}  // namespace

const char* fault_kind_name(FaultKind kind) noexcept {
  for (const auto& [k, name] : kNames) {
    if (k == kind) return name;
  }
  return "unknown";
}

std::optional<FaultKind> parse_fault_kind(std::string_view name) {
  for (const auto& [kind, spelling] : kNames) {
    if (name == spelling) return kind;
  }
  return std::nullopt;
}

}  // namespace imd::sim
