#pragma once
/// The 10 kHz control interrupt on SysTick, in two stages:
///   1. SysTick (highest priority): the sample stage latches the sensors of this instant (on a
///      board: the ADC's conversions and the encoder counter; in the processor-in-the-loop run:
///      the simulated board's sensors) and pends the control stage;
///   2. PendSV (lowest priority): the control stage runs the tick handler (the drive).
/// The sample is thus taken on time even when the computation of the last tick runs late.
///
/// Overrun: if a period ends while the control stage is still pending or running, that period's
/// sample and control are skipped and counted. The drive also times each tick with
/// execution_counts() and trips its overrun fault on a tick over its budget.
///
/// Lock-step: with `lock_step`, the counter stops at the end of each control stage and time
/// stands still until resume(). The processor-in-the-loop run advances its plant in that pause,
/// so a plant slower than real time still sees exactly one period per tick.
#include <atomic>
#include <cstdint>

#include "hal/control_timer.hpp"

namespace imd::hal::cortex_m {

/// What the high-priority stage runs at each period. Interrupt context, highest priority.
class SampleStage {
 protected:
  // Never deleted through the interface (nothing is allocated): no virtual destructor, so
  // no deleting destructor and no operator delete in the vtables of the firmware.
  ~SampleStage() = default;

 public:
  virtual void sample() noexcept = 0;
};

struct TwoStageTickConfig {
  uint32_t core_clock_Hz = 170'000'000;  ///< SysTick counts the processor clock
  uint32_t period_ns = 100'000;          ///< 10 kHz
  bool lock_step = false;                ///< stop after each tick until resume()
};

class TwoStageTick final : public hal::ControlTimer {
 public:
  /// Requires period_ns * core_clock_Hz / 1e9 to be 2 .. 2^24 counts.
  TwoStageTick(const TwoStageTickConfig& config, SampleStage& sample) noexcept;

  /// Sets the priorities (SysTick highest, PendSV lowest) and starts counting.
  void start(hal::TickHandler& handler) noexcept override;
  void stop() noexcept override;
  uint32_t period_ns() const noexcept override { return config_.period_ns; }
  uint64_t tick_count() const noexcept override { return ticks_; }
  /// Core clock counts since start(): periods passed plus the position in this one (in
  /// lock-step, the pauses are not counted). Wraps at 2^32 like a cycle counter.
  uint32_t execution_counts() const noexcept override;
  uint32_t execution_clock_Hz() const noexcept override { return config_.core_clock_Hz; }

  /// Lock-step: true once the control stage of the last period has finished (time stands
  /// still); resume() clears it and lets the counter run on to the next period.
  bool paused() const noexcept { return paused_.load(std::memory_order_acquire); }
  void resume() noexcept;

  /// Periods whose sample and control were skipped because the last control stage was late.
  uint32_t overruns() const noexcept { return overruns_; }
  /// Counts of the core clock per period.
  uint32_t counts_per_period() const noexcept { return reload_ + 1; }

  /// The two interrupt entries (SysTick_Handler and PendSV_Handler call these).
  void on_sample_interrupt() noexcept;
  void on_control_interrupt() noexcept;

 private:
  TwoStageTickConfig config_;
  SampleStage& sample_;
  hal::TickHandler* handler_ = nullptr;
  uint32_t reload_;
  uint64_t ticks_ = 0;
  volatile uint32_t count_base_ = 0;  ///< counts of the periods passed (the sample stage's)
  volatile bool control_busy_ = false;
  std::atomic<bool> paused_{false};
  uint32_t overruns_ = 0;
};

/// Binds the interrupt entries to one timer. Call before start().
void bind_tick_interrupts(TwoStageTick& timer) noexcept;

}  // namespace imd::hal::cortex_m
