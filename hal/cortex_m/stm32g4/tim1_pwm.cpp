#include "hal/cortex_m/stm32g4/tim1_pwm.hpp"

#include "hal/cortex_m/armv7m.hpp"
#include "hal/cortex_m/stm32g4/memory_map.hpp"

namespace imd::hal::cortex_m::stm32g4 {
namespace {

// TIM1 registers (RM0440 §28.6).
constexpr uintptr_t kCr1 = kTim1 + 0x00;
constexpr uintptr_t kCr2 = kTim1 + 0x04;
constexpr uintptr_t kSr = kTim1 + 0x10;
constexpr uintptr_t kEgr = kTim1 + 0x14;
constexpr uintptr_t kCcmr1 = kTim1 + 0x18;
constexpr uintptr_t kCcmr2 = kTim1 + 0x1C;
constexpr uintptr_t kCcer = kTim1 + 0x20;
constexpr uintptr_t kPsc = kTim1 + 0x28;
constexpr uintptr_t kArr = kTim1 + 0x2C;
constexpr uintptr_t kRcr = kTim1 + 0x30;
constexpr uintptr_t kCcr1 = kTim1 + 0x34;  // CCR2 0x38, CCR3 0x3C
constexpr uintptr_t kCcr4 = kTim1 + 0x40;
constexpr uintptr_t kBdtr = kTim1 + 0x44;

constexpr uint32_t kCr1Cen = 1u << 0;
constexpr uint32_t kCr1Dir = 1u << 4;         // read-only in center-aligned mode: 1 = down
constexpr uint32_t kCr1CmsCenter1 = 1u << 5;  // CMS = 01
constexpr uint32_t kCr1Arpe = 1u << 7;
constexpr uint32_t kCr2Mms2Oc4ref = 0x7u << 20;  // MMS2 = 0111: TRGO2 = OC4REFC
constexpr uint32_t kSrUif = 1u << 0;
constexpr uint32_t kEgrUg = 1u << 0;
// CCMRx output compare: OCxM [6:4] with OCxM[3] at bit 16 (channel 1/3), OCxPE bit 3; the
// second channel of the register is 8 bits up (OCxM[3] at bit 24).
constexpr uint32_t kOcPwm1 = 0x6u << 4;  // 0110: active while CNT < CCR (high side on)
constexpr uint32_t kOcPwm2 = 0x7u << 4;  // 0111: active while CNT > CCR
constexpr uint32_t kOcPreload = 1u << 3;
constexpr uint32_t kCcmrPwm1Both = (kOcPwm1 | kOcPreload) | ((kOcPwm1 | kOcPreload) << 8);
// CCER: CCxE at 4(x-1), CCxNE at 4(x-1)+2; polarities active high (gate driver inputs).
constexpr uint32_t kCcerOutputs = 0x555u;  // CC1E CC1NE CC2E CC2NE CC3E CC3NE
// BDTR: DTG [7:0], LOCK [9:8], OSSI 10, OSSR 11, BKE 12, BKP 13, AOE 14, MOE 15.
constexpr uint32_t kBdtrLock1 = 0x1u << 8;  // DTG, OISx, BKE/BKP/AOE/BKF frozen until reset
constexpr uint32_t kBdtrOssi = 1u << 10;
constexpr uint32_t kBdtrOssr = 1u << 11;
constexpr uint32_t kBdtrMoe = 1u << 15;
constexpr uint32_t kBdtrBke = 1u << 12, kBdtrBkp = 1u << 13;
constexpr uint32_t kBdtrBkf8 = 0x3u << 16;  // BKF = 0011: 8 samples at f_CK_INT (47 ns)
constexpr uint32_t kSrBif = 1u << 7;

constexpr uint32_t kUpdatePolls = 1'000'000;  // >> 3 periods at 170 MHz

bool wait_update() noexcept {
  reg32(kSr) = ~kSrUif;  // rc_w0: writing 0 clears
  for (uint32_t n = 0; n < kUpdatePolls; ++n) {
    if ((reg32(kSr) & kSrUif) != 0) {
      reg32(kSr) = ~kSrUif;
      return true;
    }
  }
  return false;
}

}  // namespace

Tim1Pwm::Tim1Pwm(const Tim1PwmConfig& c) noexcept
    : arr_(c.timer_clock_Hz / (2u * c.pwm_frequency_Hz)),
      period_s_(float(2u * arr_) / float(c.timer_clock_Hz)) {
  reg32(kCr1) = 0;  // counter stopped: CMS may only change now
  // The break input in the same write as LOCK 1, which freezes it: the comparator's output on
  // BKIN clears MOE in hardware (within the 47 ns filter), and MOE stays off until software
  // sets it again (AOE = 0).
  const uint32_t brk = c.break_input ? kBdtrBke | kBdtrBkf8 | (c.break_active_low ? 0u : kBdtrBkp)
                                     : 0u;
  reg32(kBdtr) = dead_time_code(c.dead_time_ns, c.timer_clock_Hz) | kBdtrLock1 | kBdtrOssi |
                 kBdtrOssr | brk;  // MOE = 0
  reg32(kCr1) = kCr1CmsCenter1 | kCr1Arpe;
  reg32(kCr2) = kCr2Mms2Oc4ref;  // OISx = OISxN = 0: idle level low
  reg32(kPsc) = 0;
  reg32(kArr) = arr_;
  // RCR = 1: one update per carrier period. Written before the counter starts, the update
  // comes at the overflow, i.e. the peak (RM0440 §28.3, repetition counter); start() checks it.
  reg32(kRcr) = 1;
  reg32(kCcmr1) = kCcmrPwm1Both;
  reg32(kCcmr2) = (kOcPwm1 | kOcPreload) | ((kOcPwm2 | kOcPreload) << 8);
  for (uint32_t ch = 0; ch < 3; ++ch) reg32(kCcr1 + 4 * ch) = arr_ / 2;
  reg32(kCcr4) = arr_ - c.adc_trigger_lead_counts;
  reg32(kCcer) = kCcerOutputs;
  reg32(kEgr) = kEgrUg;  // loads PSC, ARR, RCR and the CCRs; the counter restarts at 0
}

bool Tim1Pwm::start() noexcept {
  reg32(kCr1) |= kCr1Cen;
  for (int attempt = 0; attempt < 2; ++attempt) {
    if (!wait_update()) return false;
    if ((reg32(kCr1) & kCr1Dir) != 0) return true;  // counting down: the update was the peak
    // The update came at the valley. The repetition counter is reloaded from RCR at each
    // update: with RCR = 0 the next update is the next valley, and RCR = 1 written after it
    // makes the peak after that the update, and every second event from then on.
    reg32(kRcr) = 0;
    if (!wait_update()) return false;
    reg32(kRcr) = 1;
    if (!wait_update()) return false;
  }
  return (reg32(kCr1) & kCr1Dir) != 0;
}

void Tim1Pwm::set_duties(const PhaseDuties& duty) noexcept {
  const float arr = float(arr_);
  for (uint32_t ch = 0; ch < 3; ++ch) {
    float d = duty[ch];
    d = d > 0.0f ? (d < 1.0f ? d : 1.0f) : 0.0f;  // also maps NaN to 0
    reg32(kCcr1 + 4 * ch) = static_cast<uint32_t>(d * arr + 0.5f);
  }
}

void Tim1Pwm::enable() noexcept {
  // Not after a break until the drive has latched it and cleared it (clear_trip); the hardware
  // itself refuses MOE while the break input is still active.
  if (tripped()) return;
  reg32(kBdtr) |= kBdtrMoe;
}

void Tim1Pwm::clear_trip() noexcept { reg32(kSr) = ~kSrBif; }  // rc_w0: writing 0 clears

bool Tim1Pwm::tripped() const noexcept { return (reg32(kSr) & kSrBif) != 0; }

void Tim1Pwm::disable() noexcept {
  force_outputs_off();
}

bool Tim1Pwm::enabled() const noexcept {
  return (reg32(kBdtr) & kBdtrMoe) != 0;
}

void Tim1Pwm::force_outputs_off() noexcept {
  reg32(kBdtr) &= ~kBdtrMoe;
}

}  // namespace imd::hal::cortex_m::stm32g4
