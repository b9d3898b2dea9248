#pragma once
/// The independent watchdog and why the board last reset. The drive feeds the watchdog once per
/// tick, at the end of its control stage (firmware/drive.cpp): a stalled or overrunning tick
/// stops the feeding and the watchdog resets the board, whose PWM starts off. The reset cause
/// goes out in the heartbeat from the first one after boot.
#include <cstdint>

namespace imd::hal {

/// Why the board last started (the heartbeat's reset_cause).
enum class ResetCause : uint8_t {
  power_on,  ///< power-on, brown-out or the reset pin
  watchdog,  ///< the independent (or window) watchdog expired
  software,  ///< a software reset request (SYSRESETREQ)
  other,     ///< anything else the board reports (lockup, option bytes, low power)
};

class Watchdog {
 protected:
  // Never deleted through the interface (nothing is allocated): no virtual destructor, so
  // no deleting destructor and no operator delete in the vtables of the firmware.
  ~Watchdog() = default;

 public:
  /// Restarts the countdown. Tick context (the control stage only).
  virtual void feed() noexcept = 0;
};

}  // namespace imd::hal
