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
  /// A free-running high-resolution clock for measuring execution time (cycle counter on the
  /// MCU, the monotonic clock on Linux). Tick context.
  virtual uint64_t execution_clock_ns() const noexcept = 0;
};

}  // namespace imd::hal
