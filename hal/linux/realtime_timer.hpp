#pragma once
/// hal::ControlTimer on Linux: a thread that wakes at absolute deadlines on CLOCK_MONOTONIC
/// (clock_nanosleep with TIMER_ABSTIME, so the period does not drift with the tick's own
/// duration) and runs the tick handler, under SCHED_FIFO when the process may use it.
///
/// A missed deadline (the tick ended after the next period began) is counted, and the loop
/// skips to the next deadline still ahead instead of running the missed ticks back to back:
/// the tick count is the number of ticks run, the firmware's time base, and a simulated plant
/// advanced once per tick stays in lock-step with it.
///
/// Wake-up latency (wake time minus deadline) and execution time (the handler's duration) go
/// into 1 us histograms, like cyclictest's.
#include <pthread.h>

#include <atomic>
#include <cstdint>
#include <string>
#include <thread>

#include "hal/control_timer.hpp"
#include "hal/linux/latency_histogram.hpp"

namespace imd::hal {

struct RealtimeOptions {
  uint32_t period_ns = 100000;  ///< 10 kHz
  int fifo_priority = 80;       ///< SCHED_FIFO 1..99; 0 runs under the normal scheduler
  int cpu = -1;                 ///< pin the loop to this CPU; -1: any
};

/// Locks the process's memory (mlockall) so that the loop never waits for a page fault.
/// Returns "" or a warning saying why not and what it means.
std::string lock_memory();

/// Asks the kernel to keep the CPUs out of deep idle states while this object lives (writes 0
/// to /dev/cpu_dma_latency and holds it open, as cyclictest does): waking from a deep C-state,
/// or on a VM from a halted virtual CPU, adds tens of microseconds to a tick's wake-up.
class CpuIdleLatencyRequest {
 public:
  CpuIdleLatencyRequest();
  ~CpuIdleLatencyRequest();
  CpuIdleLatencyRequest(const CpuIdleLatencyRequest&) = delete;
  CpuIdleLatencyRequest& operator=(const CpuIdleLatencyRequest&) = delete;
  /// "" or why the request could not be made and what it means.
  const std::string& warning() const noexcept { return warning_; }

 private:
  int fd_ = -1;
  std::string warning_;
};

/// The wall-clock time of CLOCK_MONOTONIC in ns.
uint64_t monotonic_ns() noexcept;

class RealtimeTimer final : public ControlTimer {
 public:
  explicit RealtimeTimer(const RealtimeOptions& options) : options_(options) {}
  ~RealtimeTimer() { stop(); }
  RealtimeTimer(const RealtimeTimer&) = delete;
  RealtimeTimer& operator=(const RealtimeTimer&) = delete;

  /// Starts the loop thread. If SCHED_FIFO is refused (no CAP_SYS_NICE, or an RT budget of 0)
  /// the loop runs under the normal scheduler and warning() says so; if the thread cannot be
  /// created at all, running() stays false and warning() says why.
  void start(TickHandler& handler) noexcept override;
  /// Asks the loop to stop after the tick in progress and joins it. Safe to call twice.
  void stop() noexcept override;
  /// Ends the loop from any thread without joining (e.g. the handler itself, or a watcher).
  void request_stop() noexcept { stop_requested_.store(true); }

  uint32_t period_ns() const noexcept override { return options_.period_ns; }
  /// Ticks run so far; inside the handler, the index of the tick in progress.
  uint64_t tick_count() const noexcept override {
    return ticks_.load(std::memory_order_relaxed);
  }
  /// Nanoseconds of the monotonic clock, the low 32 bits.
  uint32_t execution_counts() const noexcept override { return uint32_t(monotonic_ns()); }
  uint32_t execution_clock_Hz() const noexcept override { return 1'000'000'000u; }

  bool running() const noexcept { return running_.load(); }
  bool realtime() const noexcept { return realtime_; }
  const std::string& warning() const noexcept { return warning_; }
  /// Deadlines passed while a tick was still running (periods skipped).
  uint64_t missed_periods() const noexcept { return missed_.load(std::memory_order_relaxed); }
  /// Read after stop().
  const LatencyHistogram& wakeup_latency() const noexcept { return wakeup_; }
  const LatencyHistogram& execution_time() const noexcept { return execution_; }

 private:
  void loop(TickHandler& handler) noexcept;

  RealtimeOptions options_;
  std::thread thread_;
  std::atomic<bool> stop_requested_{false};
  std::atomic<bool> running_{false};
  std::atomic<bool> loop_entered_{false};
  std::atomic<uint64_t> ticks_{0};
  std::atomic<uint64_t> missed_{0};
  bool realtime_ = false;
  std::string warning_;
  LatencyHistogram wakeup_;
  LatencyHistogram execution_;
};

}  // namespace imd::hal
