// The pieces of the Linux real-time loop that run without CAN or GPIO hardware: the lock-free
// ring between the tick and the CAN I/O thread, the latency histogram, and the absolute-deadline
// timer (checked for what it does, never for how fast: this host is shared).
#include <gtest/gtest.h>

#include <atomic>
#include <cstdint>
#include <thread>
#include <vector>

#include "hal/can_bus.hpp"
#include "hal/linux/latency_histogram.hpp"
#include "hal/linux/realtime_timer.hpp"
#include "hal/spsc_ring.hpp"

namespace imd::hal {
namespace {

TEST(SpscRing, HoldsItsWholeCapacityInOrderAndRefusesMore) {
  SpscRing<int, 4> ring;
  for (int i = 0; i < 4; ++i) EXPECT_TRUE(ring.try_push(i));
  EXPECT_FALSE(ring.try_push(99));  // full: nothing is overwritten
  EXPECT_EQ(ring.size(), 4u);
  int value = -1;
  for (int i = 0; i < 4; ++i) {
    ASSERT_TRUE(ring.try_pop(value));
    EXPECT_EQ(value, i);
  }
  EXPECT_FALSE(ring.try_pop(value));
  EXPECT_EQ(ring.front(), nullptr);
}

TEST(SpscRing, FrontKeepsAnItemUntilPopped) {
  SpscRing<CanFrame, 8> ring;
  CanFrame frame;
  frame.id = 0x123;
  ASSERT_TRUE(ring.try_push(frame));
  ASSERT_NE(ring.front(), nullptr);
  EXPECT_EQ(ring.front()->id, 0x123);
  EXPECT_EQ(ring.size(), 1u);  // a refused send leaves the frame queued
  ring.pop();
  EXPECT_EQ(ring.front(), nullptr);
}

TEST(SpscRing, PassesEveryItemOnceInOrderBetweenTwoThreads) {
  // Far more items than slots, so that the indices wrap many times and both sides meet full
  // and empty rings; any lost, repeated or reordered item breaks the sequence.
  constexpr uint32_t kItems = 2'000'000;
  SpscRing<uint32_t, 64> ring;
  std::thread producer([&ring] {
    for (uint32_t i = 0; i < kItems;) {
      if (ring.try_push(i)) ++i;
    }
  });
  uint32_t expected = 0;
  bool in_order = true;
  while (expected < kItems) {
    uint32_t value = 0;
    if (!ring.try_pop(value)) continue;
    in_order = in_order && value == expected;
    ++expected;
  }
  producer.join();
  EXPECT_TRUE(in_order);
  EXPECT_EQ(ring.size(), 0u);
}

TEST(LatencyHistogram, QuantilesAreUpperBinEdgesAndLongSamplesOverflow) {
  LatencyHistogram h(100);  // 0..99 us
  for (int i = 0; i < 98; ++i) h.record(10'500);  // bin 10
  h.record(50'200);                               // bin 50
  h.record(250'000);                              // overflow
  EXPECT_EQ(h.count(), 100u);
  EXPECT_EQ(h.overflows(), 1u);
  EXPECT_DOUBLE_EQ(h.quantile_us(0.5), 11.0);  // half the samples took less than 11 us
  EXPECT_DOUBLE_EQ(h.quantile_us(0.98), 11.0);  // the 98th of 100 samples is still in bin 10
  EXPECT_DOUBLE_EQ(h.quantile_us(0.99), 51.0);  // the 99th is the one in bin 50
  EXPECT_DOUBLE_EQ(h.quantile_us(1.0), 250.0);  // the overflow bin reports the maximum
  EXPECT_EQ(h.max_ns(), 250'000u);
  EXPECT_EQ(h.count_at_least_us(50), 2u);
  EXPECT_NEAR(h.mean_ns(), (98 * 10'500.0 + 50'200.0 + 250'000.0) / 100.0, 1e-9);
  h.record(-5);  // a clock that stepped back counts as 0, not as a huge unsigned value
  EXPECT_EQ(h.bins()[0], 1u);
}

TEST(LatencyHistogram, EmptyHasNoQuantiles) {
  const LatencyHistogram h;
  EXPECT_EQ(h.quantile_us(0.99), 0.0);
  EXPECT_EQ(h.mean_ns(), 0.0);
}

/// Records the tick index the timer reports inside each call.
class CountingTick final : public TickHandler {
 public:
  explicit CountingTick(const ControlTimer& timer) : timer_(timer) {}
  void on_tick() noexcept override {
    consecutive_ = consecutive_ && timer_.tick_count() == calls_;
    calls_.fetch_add(1);
  }
  uint64_t calls() const noexcept { return calls_.load(); }
  bool consecutive() const noexcept { return consecutive_; }

 private:
  const ControlTimer& timer_;
  std::atomic<uint64_t> calls_{0};
  bool consecutive_ = true;
};

TEST(RealtimeTimer, RunsTheHandlerOncePerTickWithConsecutiveIndicesUntilStopped) {
  RealtimeOptions options;
  options.period_ns = 1'000'000;  // 1 kHz: the test is about function, not timing
  options.fifo_priority = 0;      // no privileges needed
  RealtimeTimer timer(options);
  CountingTick tick(timer);
  timer.start(tick);
  ASSERT_TRUE(timer.running()) << timer.warning();
  // Wait for 20 ticks (20 ms at the nominal rate), however slowly this host runs them.
  for (int waited_ms = 0; tick.calls() < 20 && waited_ms < 10'000; ++waited_ms) {
    std::this_thread::sleep_for(std::chrono::milliseconds(1));
  }
  timer.stop();
  EXPECT_FALSE(timer.running());
  const uint64_t calls = tick.calls();
  EXPECT_GE(calls, 20u);
  EXPECT_EQ(timer.tick_count(), calls);
  EXPECT_TRUE(tick.consecutive());
  // Every tick has one wake-up and one execution sample; skipped periods are not ticks.
  EXPECT_EQ(timer.wakeup_latency().count(), calls);
  EXPECT_EQ(timer.execution_time().count(), calls);
  std::this_thread::sleep_for(std::chrono::milliseconds(5));
  EXPECT_EQ(tick.calls(), calls);  // stopped means stopped
  timer.stop();                    // a second stop is harmless
}

/// A tick that takes 2.5 periods: each one passes two further deadlines.
class SlowTick final : public TickHandler {
 public:
  void on_tick() noexcept override {
    const uint64_t until = monotonic_ns() + 2'500'000;
    while (monotonic_ns() < until) {
    }
    calls.fetch_add(1);
  }
  std::atomic<uint64_t> calls{0};
};

TEST(RealtimeTimer, SkipsThePeriodsATickOverranInsteadOfRunningThemLate) {
  RealtimeOptions options;
  options.period_ns = 1'000'000;
  options.fifo_priority = 0;
  RealtimeTimer timer(options);
  SlowTick tick;
  timer.start(tick);
  for (int waited_ms = 0; tick.calls.load() < 5 && waited_ms < 10'000; ++waited_ms) {
    std::this_thread::sleep_for(std::chrono::milliseconds(1));
  }
  timer.stop();
  const uint64_t calls = tick.calls.load();
  ASSERT_GE(calls, 5u);
  // A 2.5 ms tick ends past two more 1 ms deadlines, or more if the host preempted it.
  EXPECT_GE(timer.missed_periods(), 2 * calls);
  EXPECT_EQ(timer.tick_count(), calls);
}

TEST(RealtimeTimer, ReportsARefusedRealtimePriorityOrRunsWithIt) {
  RealtimeOptions options;
  options.period_ns = 1'000'000;
  options.fifo_priority = 10;
  RealtimeTimer timer(options);
  CountingTick tick(timer);
  timer.start(tick);
  ASSERT_TRUE(timer.running());
  timer.stop();
  // As root SCHED_FIFO is granted; otherwise the timer says why not, and still runs.
  if (!timer.realtime()) {
    EXPECT_NE(timer.warning().find("SCHED_FIFO priority 10 refused"), std::string::npos);
  } else {
    EXPECT_TRUE(timer.warning().empty());
  }
}

}  // namespace
}  // namespace imd::hal
