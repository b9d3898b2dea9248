#pragma once
/// The periodic control interrupt. The application registers one handler; the timer calls it
/// once per period, after the ADC and encoder have latched their samples.
#include <cstdint>

namespace imd::hal {

/// What the timer calls each period.
class TickHandler {
 protected:
  // Never deleted through the interface (nothing is allocated): no virtual destructor, so
  // no deleting destructor and no operator delete in the vtables of the firmware.
  ~TickHandler() = default;

 public:
  virtual void on_tick() noexcept = 0;
};

class ControlTimer {
 protected:
  // Never deleted through the interface (nothing is allocated): no virtual destructor, so
  // no deleting destructor and no operator delete in the vtables of the firmware.
  ~ControlTimer() = default;

 public:
  /// Starts calling `handler` every period. The handler must outlive the timer's running.
  virtual void start(TickHandler& handler) noexcept = 0;
  virtual void stop() noexcept = 0;
  /// The control period, fixed at configuration.
  virtual uint32_t period_ns() const noexcept = 0;
  /// Number of periods since start: the control time base. Tick context.
  virtual uint64_t tick_count() const noexcept = 0;
  /// A free-running counter for timing the tick and its stages: the core's cycles on the MCU,
  /// nanoseconds of the monotonic clock on Linux. It wraps at 2^32 counts, so only differences
  /// over less than 2^32 counts mean anything. One cheap read (the drive reads it once per
  /// stage). Tick context.
  virtual uint32_t execution_counts() const noexcept = 0;
  /// The rate of execution_counts(), fixed at configuration.
  virtual uint32_t execution_clock_Hz() const noexcept = 0;
};

}  // namespace imd::hal
