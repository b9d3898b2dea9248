#pragma once
/// A reference source filled ahead of the tick, as a trajectory generator of lower priority
/// would fill it: the tick only reads a ring of precomputed references. The processor-in-the-
/// loop run fills it between ticks, so that the double-precision profiles (a sine) are not
/// counted in the tick's cost. The drive asks for at most k + kDepth - 1 at tick k (the DSMC
/// two ticks ahead, three when it reads the next tick's ahead after the write, the current-fed
/// law one T0 ahead).
#include <array>
#include <cstdint>

#include "firmware/reference_source.hpp"
#include "hal_sim/drive/scenario_profiles.hpp"

namespace imd::sim {

template <typename T>
class LookaheadReferences final : public firmware::ReferenceSource<T> {
 public:
  static constexpr uint64_t kDepth = 32;

  LookaheadReferences(const ScenarioProfiles& profiles, double period_s) noexcept
      : profiles_(profiles), period_s_(period_s) {}

  /// Outside the tick: makes ticks k .. k + kDepth - 1 available (k never decreases).
  void fill_from(uint64_t k) noexcept {
    for (; next_ < k + kDepth; ++next_) {
      ring_[next_ % kDepth] = reference_at_tick<T>(profiles_, period_s_, next_);
    }
  }
  /// Tick context: a read of the ring.
  firmware::Reference<T> at_tick(uint64_t k) const noexcept override { return ring_[k % kDepth]; }

 private:
  const ScenarioProfiles& profiles_;
  double period_s_;
  uint64_t next_ = 0;
  std::array<firmware::Reference<T>, kDepth> ring_{};
};

}  // namespace imd::sim
