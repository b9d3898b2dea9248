#pragma once
/// The tick's stages, and the clock that times them. Each stage's duration is kept in the tick
/// record in counts of the control timer's execution clock (hal::ControlTimer), one read per
/// stage; the telemetry and the simulation summary turn counts into time. Tick context.
#include <array>
#include <cstdint>

#include "hal/control_timer.hpp"

namespace imd::firmware {

enum class Stage : uint8_t { sense, estimate, supervise, law, modulate, protect, actuate, publish };
inline constexpr int kStageCount = 8;

inline constexpr std::array<const char*, kStageCount> kStageNames = {
    "sense", "estimate", "supervise", "law", "modulate", "protect", "actuate", "publish"};

/// Durations of one tick's stages, in execution-clock counts.
using StageCounts = std::array<uint32_t, kStageCount>;

class StageClock {
 public:
  /// Starts timing a tick (the first read). Its stages are timed when `timed`; a drive times
  /// one tick in N (DriveConfig::stage_timing_period_ticks), because every read of the clock
  /// costs a share of the tick itself.
  StageClock(const hal::ControlTimer& timer, StageCounts& counts, bool timed) noexcept
      : timer_(timer),
        counts_(counts),
        timed_(timed),
        start_(timer.execution_counts()),
        last_(start_) {}

  /// Ends `stage`: its duration is the time since the last lap.
  void lap(Stage stage) noexcept {
    if (timed_) lap_total(stage);
  }
  /// Ends `stage` and returns the counts since the start of the tick: the clock is read on
  /// every tick here (the drive checks its budget on every tick).
  uint32_t lap_total(Stage stage) noexcept {
    const uint32_t now = timer_.execution_counts();
    counts_[static_cast<int>(stage)] = now - last_;  // modulo 2^32: the counter may wrap
    last_ = now;
    return now - start_;
  }

 private:
  const hal::ControlTimer& timer_;
  StageCounts& counts_;
  bool timed_;
  uint32_t start_, last_;
};

}  // namespace imd::firmware
