#include "hal/cortex_m/stm32g4/adc_tick.hpp"

#include "hal/cortex_m/armv7m.hpp"
#include "hal/cortex_m/stm32g4/memory_map.hpp"
#include "hal/cortex_m/stm32g4/nvic_dwt.hpp"

namespace imd::hal::cortex_m::stm32g4 {
namespace {

// The one timer the interrupt entries serve: an interrupt handler has no other way to reach
// its object.
AdcTick* g_adc_tick = nullptr;

constexpr uint32_t kSequenceSkewLimit_cycles = 340;  // 2 us at 170 MHz

}  // namespace

void bind_adc_tick_interrupts(AdcTick& timer) noexcept {
  g_adc_tick = &timer;
}

AdcTick::AdcTick(const AdcTickConfig& config, AdcInjected& adc, SampleStage& sample) noexcept
    : config_(config),
      adc_(adc),
      sample_(sample) {}

void AdcTick::start(hal::TickHandler& handler) noexcept {
  handler_ = &handler;
  // ADC1_2 highest, PendSV lowest (SHPR3 [23:16]): the sample preempts a late control stage.
  reg32(kScbShpr3) = (reg32(kScbShpr3) & ~(0xFFu << 16)) | (0xFFu << 16);
  nvic_set_priority(kIrqAdc1_2, kPriorityHighest);
  adc_.acknowledge();  // a sequence that ended before start() is not a tick
  adc_.set_interrupt(true);
  nvic_enable(kIrqAdc1_2);
}

void AdcTick::stop() noexcept {
  nvic_disable(kIrqAdc1_2);
  adc_.set_interrupt(false);
  handler_ = nullptr;
}

uint32_t AdcTick::execution_counts() const noexcept {
  return cycle_count();
}

void AdcTick::on_sample_interrupt() noexcept {
  // Both ADCs end together (same trigger, clock and sequence length) and either raises this
  // interrupt. The second one's flag may pend it again while it runs: an entry with neither
  // flag set is that repeat. With one flag set, wait briefly for the other; if it does not
  // end, the sample goes on with its last codes and is counted (the drive's stuck-ADC check
  // trips on codes that do not move).
  uint32_t ended = adc_.ended_sequences();
  if (ended == 0) return;
  const uint32_t first = cycle_count();
  while (ended != AdcInjected::kBothEnded) {
    if (cycle_count() - first > kSequenceSkewLimit_cycles) {
      ++sample_faults_;
      break;
    }
    ended = adc_.ended_sequences();
  }
  adc_.acknowledge();
  if (control_busy_) {
    ++overruns_;  // the last control stage has not finished: skip this period
    return;
  }
  sample_.sample();
  control_busy_ = true;
  reg32(kScbIcsr) = kIcsrPendSvSet;
}

void AdcTick::on_control_interrupt() noexcept {
  if (handler_ != nullptr) handler_->on_tick();
  ++ticks_;
  control_busy_ = false;
}

}  // namespace imd::hal::cortex_m::stm32g4

extern "C" void ADC1_2_IRQHandler() {
  if (imd::hal::cortex_m::stm32g4::g_adc_tick != nullptr) {
    imd::hal::cortex_m::stm32g4::g_adc_tick->on_sample_interrupt();
  }
}

extern "C" void PendSV_Handler() {
  if (imd::hal::cortex_m::stm32g4::g_adc_tick != nullptr) {
    imd::hal::cortex_m::stm32g4::g_adc_tick->on_control_interrupt();
  }
}
