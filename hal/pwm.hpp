#pragma once
/// Three-phase PWM output. Duties are high-side on-time fractions in [0, 1] of a center-aligned
/// carrier. Disabled means every switch off: the inverter's safe state.
#include <array>

namespace imd::hal {

using PhaseDuties = std::array<float, 3>;  ///< phases a, b, c

class Pwm {
 protected:
  // Never deleted through the interface (nothing is allocated): no virtual destructor, so
  // no deleting destructor and no operator delete in the vtables of the firmware.
  ~Pwm() = default;

 public:
  /// Latches duties for the next carrier period. Tick context.
  virtual void set_duties(const PhaseDuties& duty) noexcept = 0;
  /// Starts switching with the last duties written. Tick context.
  virtual void enable() noexcept = 0;
  /// All switches off at once (the safe state). Tick context; also from fault handlers.
  virtual void disable() noexcept = 0;
  virtual bool enabled() const noexcept = 0;
  /// The power stage's own protection (a hardware over-current comparator on the timer's break
  /// input) turned the outputs off since the last enable, without software. Tick context.
  virtual bool tripped() const noexcept { return false; }
  /// Forgets a trip (the drive's fault was cleared); until then enable() is refused.
  virtual void clear_trip() noexcept {}
  /// Carrier period, fixed at configuration.
  virtual float period_s() const noexcept = 0;
};

}  // namespace imd::hal
