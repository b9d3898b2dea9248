#pragma once
/// The CMSDK APB watchdog (Arm DDI0479C; QEMU's mps2-an386 maps one at 0x40008000, clocked at
/// the core clock, its interrupt wired to NMI). It counts down from its load value; reaching
/// zero the first time raises its interrupt (the NMI) and reloads; reaching zero again with the
/// interrupt still raised resets the system. feed() clears the interrupt, which also reloads.
/// The MPS2 keeps no reset cause, so the NMI records one that survives the reset
/// (hal/cortex_m/reset_record.hpp).
#include <cstdint>

#include "hal/watchdog.hpp"

namespace imd::hal::cortex_m {

class CmsdkWatchdog final : public hal::Watchdog {
 public:
  /// Starts it: the first expiry `timeout_counts` of its clock after the last feed, the reset
  /// as long again after that.
  CmsdkWatchdog(uintptr_t base, uint32_t timeout_counts) noexcept;
  void feed() noexcept override;
  /// Its interrupt is raised: it expired once since the last feed.
  bool expired() const noexcept;

 private:
  volatile uint32_t& reg(uintptr_t offset) const noexcept {
    return *reinterpret_cast<volatile uint32_t*>(base_ + offset);
  }
  uintptr_t base_;
};

}  // namespace imd::hal::cortex_m
