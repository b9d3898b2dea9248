#pragma once
/// The commissioning run as the drive's tick sees it: the standstill steps, then, when the
/// shaft may turn, the rotating step for inertia and friction, which starts from the standstill
/// result. Progress is one step code for the telemetry (the protocol's identify_step table).
/// Tick context; no allocation (the rotating step is built in place when its turn comes).
#include <cstdint>
#include <optional>

#include "firmware/identification/inertia_identifier.hpp"
#include "firmware/identification/standstill_identifier.hpp"

namespace imd::firmware {

template <typename T>
class Commissioning {
 public:
  using Vec2 = control::Vec2<T>;

  /// `rotating`: the rotating step's plan, or none to keep the mechanics.
  Commissioning(const IdentificationPlan& standstill, const std::optional<InertiaPlan>& rotating)
      : standstill_(standstill) {
    if (rotating) rotating_.emplace(*rotating);
  }

  Vec2 step(const Vec2& i_A, int32_t encoder_delta_counts) noexcept {
    if (inertia_) return inertia_->step(i_A, encoder_delta_counts);
    const Vec2 u = standstill_.step(i_A);
    if (standstill_.current_step() == IdentificationStep::done && rotating_) {
      inertia_.emplace(*rotating_, standstill_.result());
    }
    return u;
  }

  bool finished() const noexcept {
    if (inertia_) return inertia_->finished();
    return standstill_.finished() && !(rotating_ && succeeded_standstill());
  }
  /// Finished with a result: the electrical parameters, and the mechanics measured or kept.
  bool succeeded() const noexcept {
    if (inertia_) return inertia_->current_step() == InertiaStep::done;
    return succeeded_standstill();
  }
  /// The protocol's identify_step code: 0-3 standstill steps, 4 done, 5 failed, 7-11 the
  /// rotating step's flux_up, accelerate, coast, brake, field_down.
  uint8_t step_code() const noexcept {
    if (!inertia_) return static_cast<uint8_t>(standstill_.current_step());
    switch (inertia_->current_step()) {
      case InertiaStep::done:
        return 4;
      case InertiaStep::failed:
        return 5;
      default:
        return static_cast<uint8_t>(7 + int(inertia_->current_step()));
    }
  }
  /// The protocol's identify_failure code (7: done, the rotor did not turn, mechanics kept;
  /// 8 wrong_direction, 9 overspeed, 10 not_at_rest, 11 stalled).
  uint8_t failure_code() const noexcept {
    if (!inertia_) return static_cast<uint8_t>(standstill_.failure());
    switch (inertia_->outcome()) {
      case InertiaOutcome::voltage_limit:
        return static_cast<uint8_t>(IdentificationFailure::voltage_limit);
      case InertiaOutcome::implausible:
        return static_cast<uint8_t>(IdentificationFailure::implausible);
      case InertiaOutcome::no_motion:
        return 7;
      case InertiaOutcome::wrong_direction:
        return 8;
      case InertiaOutcome::overspeed:
        return 9;
      case InertiaOutcome::not_at_rest:
        return 10;
      case InertiaOutcome::stalled:
        return 11;
      case InertiaOutcome::running:
      case InertiaOutcome::measured:
        break;
    }
    return 0;
  }
  T fraction() const noexcept { return inertia_ ? inertia_->fraction() : standstill_.fraction(); }

  const StandstillResult<T>& electrical() const noexcept { return standstill_.result(); }
  /// The measured mechanics, if the rotating step ran and measured them.
  std::optional<Mechanics<T>> mechanics() const noexcept {
    if (inertia_ && inertia_->outcome() == InertiaOutcome::measured) return inertia_->result();
    return std::nullopt;
  }
  const StandstillIdentifier<T>& standstill() const noexcept { return standstill_; }
  const InertiaIdentifier<T>* rotating() const noexcept { return inertia_ ? &*inertia_ : nullptr; }

 private:
  bool succeeded_standstill() const noexcept {
    return standstill_.current_step() == IdentificationStep::done;
  }

  StandstillIdentifier<T> standstill_;
  std::optional<InertiaSettings<T>> rotating_;
  std::optional<InertiaIdentifier<T>> inertia_;
};

}  // namespace imd::firmware
