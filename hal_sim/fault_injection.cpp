#include "hal_sim/fault_injection.hpp"

#include <array>
#include <cmath>
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

const char* fault_parameter_error(const FaultInjection& fault) noexcept {
  const auto positive_finite = [](double value) { return value > 0.0 && std::isfinite(value); };
  const bool phase_ok = fault.phase >= 0 && fault.phase <= 2;
  switch (fault.kind) {
    case FaultKind::overcurrent:
      if (!phase_ok) return "overcurrent: phase must be 0, 1 or 2";
      if (!positive_finite(fault.surge_A)) return "overcurrent: surge_A must be > 0 and finite";
      return nullptr;
    case FaultKind::overvoltage:
      return positive_finite(fault.bus_V) ? nullptr : "overvoltage: bus_V must be > 0 and finite";
    case FaultKind::undervoltage:
      return positive_finite(fault.bus_V) ? nullptr : "undervoltage: bus_V must be > 0 and finite";
    case FaultKind::phase_loss:
      return phase_ok ? nullptr : "phase_loss: phase must be 0, 1 or 2";
    case FaultKind::overrun:
      // The bound keeps the stall in nanoseconds far inside uint64_t.
      return fault.stall_us > 0.0 && fault.stall_us < 1e9
                 ? nullptr
                 : "overrun: stall_us must be > 0 and below 1e9";
    case FaultKind::encoder_loss:
    case FaultKind::adc_stuck:
    case FaultKind::can_silence:
      return nullptr;
  }
  return "unknown fault kind";
}

std::optional<FaultKind> parse_fault_kind(std::string_view name) {
  for (const auto& [kind, spelling] : kNames) {
    if (name == spelling) return kind;
  }
  return std::nullopt;
}

}  // namespace imd::sim
