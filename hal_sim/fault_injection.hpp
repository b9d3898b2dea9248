#pragma once
/// Faults the simulated board can suffer, each a physical event on the board or the motor.
/// SimBoard::inject applies one at once; the scenario runner calls it at the start of the first
/// tick with t >= at_s, before that tick runs.
#include <limits>
#include <optional>
#include <string_view>

namespace imd::sim {

enum class FaultKind {
  /// A short in the load: a current surge of surge_A added to the stator current along phase
  /// `phase`'s axis (that phase gets +surge_A, the two others -surge_A/2 each), seen by the next
  /// ADC conversion. The plant's dynamics then carry it on.
  overcurrent,
  /// The DC bus rises to bus_V from now on (until another bus fault): the ADC measures it, the
  /// inverter applies it.
  overvoltage,
  /// The DC bus sags to bus_V from now on, as overvoltage.
  undervoltage,
  /// The encoder's signal is lost: its count freezes (no more edges).
  encoder_loss,
  /// The ADC stops converting: every later sample repeats its last conversion.
  adc_stuck,
  /// Phase `phase` opens (a blown fuse, a broken lead): its current is zero from now on. With
  /// the star point floating, the open terminal's voltage is whatever keeps it so. A second
  /// open phase leaves no current path at all.
  phase_loss,
  /// From now on every tick takes stall_us longer on the execution clock, as if an interrupt of
  /// higher priority stole that time inside the tick (a later overrun replaces the stall).
  overrun,
  /// The host falls silent: every frame for the firmware is lost from now on; the frames the
  /// firmware sends are still collected.
  can_silence,
};

inline constexpr int kFaultKindCount = 8;  ///< the kinds are 0 .. kFaultKindCount - 1
static_assert(static_cast<int>(FaultKind::can_silence) + 1 == kFaultKindCount);

/// The scenario spelling of a kind, e.g. "encoder_loss".
const char* fault_kind_name(FaultKind kind) noexcept;
/// The kind of a scenario spelling; nullopt for anything else.
std::optional<FaultKind> parse_fault_kind(std::string_view name);

/// One fault and its parameters; only those of its kind are used.
struct FaultInjection {
  double at_s = 0.0;  ///< simulated time at which it happens
  FaultKind kind = FaultKind::overcurrent;
  double surge_A = std::numeric_limits<double>::quiet_NaN();  ///< overcurrent: surge, > 0
  int phase = 0;  ///< overcurrent and phase_loss: the phase, 0..2 (a, b, c)
  double bus_V = std::numeric_limits<double>::quiet_NaN();  ///< over/undervoltage: the new bus
  double stall_us = 1000.0;                                 ///< overrun: time stolen per tick
  /// The fault is repaired at this time (after at_s): the bus back to nominal, the encoder
  /// counting again from where it froze, the ADC converting, the phase closed, the stall and
  /// the silence over. An over-current surge is over at once. Infinite: never.
  double until_s = std::numeric_limits<double>::infinity();
};

/// Why SimBoard::inject would refuse this fault: a static message naming the kind and the
/// parameter out of its range (phase outside 0..2; a surge or bus that is not > 0 and finite; a
/// stall not in (0, 1e9) us), e.g. "overcurrent: surge_A must be > 0 and finite". nullptr when
/// the fault is valid.
const char* fault_parameter_error(const FaultInjection& fault) noexcept;

}  // namespace imd::sim
