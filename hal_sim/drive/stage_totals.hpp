#pragma once
/// The drive's stage durations summed over a run, from the ticks whose stages it timed
/// (firmware/stages/stage_clock.hpp), in execution-clock counts. No heap.
#include <cstdint>

#include "firmware/stages/stage_clock.hpp"

namespace imd::sim {

struct StageTotals {
  uint64_t counts[firmware::kStageCount] = {};
  uint64_t ticks = 0;

  void add(const firmware::StageCounts& c) noexcept {
    for (int i = 0; i < firmware::kStageCount; ++i) counts[i] += c[i];
    ++ticks;
  }
};

}  // namespace imd::sim
