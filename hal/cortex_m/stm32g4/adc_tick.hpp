#pragma once
/// The 10 kHz control interrupt of the STM32G4 board, in two stages like
/// hal/cortex_m/two_stage_tick.hpp, but paced by the PWM carrier instead of SysTick:
///   1. ADC1_2 (highest priority): TIM1 TRGO2 starts the injected conversions just before the
///      carrier peak; their end of sequence (JEOS) raises this interrupt. The sample stage
///      latches the ADC codes and the encoder counter of this instant and pends the control
///      stage;
///   2. PendSV (lowest priority): the control stage runs the tick handler (the drive).
/// The sample is thus taken at the carrier peak even when the last computation runs late.
///
/// Overrun: if a sample arrives while the control stage is still pending or running, that
/// period's sample and control are skipped and counted (as in TwoStageTick). The drive also
/// times each tick and its stages with execution_counts(), the DWT cycle counter (32 bits,
/// wrapping every 25 s at 170 MHz), and trips its overrun fault over its budget.
#include <cstdint>

#include "hal/control_timer.hpp"
#include "hal/cortex_m/stm32g4/adc_injected.hpp"
#include "hal/cortex_m/stm32g4/tim_encoder.hpp"
#include "hal/cortex_m/two_stage_tick.hpp"

namespace imd::hal::cortex_m::stm32g4 {

/// The board's sample stage: the ADC codes and the encoder count of the carrier peak.
class AdcEncoderSample final : public SampleStage {
 public:
  AdcEncoderSample(AdcInjected& adc, TimEncoder& encoder) noexcept : adc_(adc), encoder_(encoder) {}
  void sample() noexcept override {
    adc_.latch();
    encoder_.latch();
  }

 private:
  AdcInjected& adc_;
  TimEncoder& encoder_;
};

struct AdcTickConfig {
  uint32_t core_clock_Hz = 170'000'000;  ///< DWT counts the processor clock
  uint32_t period_ns = 100'000;          ///< the PWM carrier period (tim1_pwm.hpp)
};

class AdcTick final : public hal::ControlTimer {
 public:
  /// `adc` is the interrupt source (its end of sequence); `sample` what the sample stage runs.
  AdcTick(const AdcTickConfig& config, AdcInjected& adc, SampleStage& sample) noexcept;

  /// Sets the priorities (ADC1_2 highest, PendSV lowest) and enables the end-of-sequence
  /// interrupt: the first tick follows the next carrier peak. TIM1 must be running.
  void start(hal::TickHandler& handler) noexcept override;
  void stop() noexcept override;
  uint32_t period_ns() const noexcept override { return config_.period_ns; }
  uint64_t tick_count() const noexcept override { return ticks_; }
  /// The DWT cycle counter: one register read. Tick context.
  uint32_t execution_counts() const noexcept override;
  uint32_t execution_clock_Hz() const noexcept override { return config_.core_clock_Hz; }

  /// Periods whose sample and control were skipped because the last control stage was late.
  uint32_t overruns() const noexcept { return overruns_; }
  /// Samples taken although one of the two ADCs had not ended its sequence (stale codes).
  uint32_t sample_faults() const noexcept { return sample_faults_; }

  /// The two interrupt entries (ADC1_2_IRQHandler and PendSV_Handler call these).
  void on_sample_interrupt() noexcept;
  void on_control_interrupt() noexcept;

 private:
  AdcTickConfig config_;
  AdcInjected& adc_;
  SampleStage& sample_;
  hal::TickHandler* handler_ = nullptr;
  uint64_t ticks_ = 0;
  volatile bool control_busy_ = false;
  uint32_t overruns_ = 0;
  uint32_t sample_faults_ = 0;
};

/// Binds the interrupt entries to one timer. Call before start().
void bind_adc_tick_interrupts(AdcTick& timer) noexcept;

}  // namespace imd::hal::cortex_m::stm32g4
