#include "hal/cortex_m/two_stage_tick.hpp"

#include "hal/cortex_m/armv7m.hpp"

namespace imd::hal::cortex_m {
namespace {

// The one timer the interrupt entries serve: an interrupt handler has no other way to reach
// its object.
TwoStageTick* g_tick_timer = nullptr;

}  // namespace

void bind_tick_interrupts(TwoStageTick& timer) noexcept { g_tick_timer = &timer; }

TwoStageTick::TwoStageTick(const TwoStageTickConfig& config, SampleStage& sample) noexcept
    : config_(config),
      sample_(sample),
      reload_(static_cast<uint32_t>(uint64_t(config.period_ns) * config.core_clock_Hz /
                                    1'000'000'000u) -
              1u) {}

void TwoStageTick::start(hal::TickHandler& handler) noexcept {
  handler_ = &handler;
  // SysTick highest (0), PendSV lowest (0xFF): the sample preempts a late control stage.
  reg32(kScbShpr3) = (reg32(kScbShpr3) & 0x0000FFFFu) | (0x00u << 24) | (0xFFu << 16);
  reg32(kSysTickCsr) = 0;
  reg32(kSysTickRvr) = reload_;
  reg32(kSysTickCvr) = 0;  // any write clears the counter: a full period to the first tick
  reg32(kSysTickCsr) = kSysTickEnable | kSysTickInterrupt | kSysTickCoreClock;
}

void TwoStageTick::stop() noexcept {
  reg32(kSysTickCsr) = 0;
  handler_ = nullptr;
}

void TwoStageTick::resume() noexcept {
  paused_.store(false, std::memory_order_release);
  reg32(kSysTickCsr) = kSysTickEnable | kSysTickInterrupt | kSysTickCoreClock;
}

uint32_t TwoStageTick::execution_counts() const noexcept {
  // The sample stage may preempt between the reads (it adds a period to the base): retry.
  for (;;) {
    const uint32_t base = count_base_;
    const uint32_t value = reg32(kSysTickCvr);
    if (base == count_base_) return base + (reload_ - value);
  }
}

void TwoStageTick::on_sample_interrupt() noexcept {
  count_base_ = count_base_ + (reload_ + 1);
  if (control_busy_) {
    ++overruns_;  // the last control stage has not finished: skip this period
    return;
  }
  sample_.sample();
  control_busy_ = true;
  reg32(kScbIcsr) = kIcsrPendSvSet;
}

void TwoStageTick::on_control_interrupt() noexcept {
  if (handler_ != nullptr) handler_->on_tick();
  ++ticks_;
  if (config_.lock_step) {
    reg32(kSysTickCsr) = 0;  // time stands still until resume()
    paused_.store(true, std::memory_order_release);
  }
  control_busy_ = false;
}

}  // namespace imd::hal::cortex_m

extern "C" void SysTick_Handler() {
  if (imd::hal::cortex_m::g_tick_timer != nullptr) {
    imd::hal::cortex_m::g_tick_timer->on_sample_interrupt();
  }
}

extern "C" void PendSV_Handler() {
  if (imd::hal::cortex_m::g_tick_timer != nullptr) {
    imd::hal::cortex_m::g_tick_timer->on_control_interrupt();
  }
}
