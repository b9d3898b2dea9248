#pragma once
/// Whether a limit keeps the drive from its reference, and which one. Each tick the law says
/// whether a limit cut what its speed or flux channel wanted (LawDiagnostics::limit); a limit
/// that holds for most of a window is a limitation the user must hear of: the `limited` field of
/// the heartbeat and of the summary. Tick context except construction.
///
/// The window is four time constants of the default speed loop (control/ifoc_design.hpp), so
/// that a limit touched for a tick or two by a transient, or by the sliding-mode law's
/// occasional step onto the voltage disk, is not reported, and a limit that holds the speed back
/// is reported while the speed loop would still be settling. A leaky count (+1 a limited tick,
/// -1 a free one) must reach the window to raise the flag and fall back to zero to clear it:
/// a limit active in more than half of the ticks, for long enough. The reason is the limit
/// that dominated the recent ticks.
#include <algorithm>
#include <cmath>
#include <cstdint>

#include "control/ifoc_design.hpp"
#include "control/real.hpp"
#include "firmware/drive_config.hpp"

namespace imd::firmware {

/// What held the drive back (the heartbeat's 2-bit `limited` signal).
enum class Limitation : uint8_t {
  none = 0,
  voltage = 1,  ///< the inverter's voltage: above base speed, or a low bus
  current = 2,  ///< the current limit
  torque = 3,   ///< the configured torque limit
  /// The law's input left the feasible set (voltage and current disks, control/input_disk.hpp):
  /// the drive resolves it to voltage or current. Never reported as such.
  input = 4,
};

/// The value table's name ("none", "voltage", "current", "torque").
constexpr const char* limitation_name(Limitation l) noexcept {
  switch (l) {
    case Limitation::voltage: return "voltage";
    case Limitation::current: return "current";
    case Limitation::torque: return "torque";
    case Limitation::input: return "input";
    case Limitation::none: break;
  }
  return "none";
}

/// Ticks of a limit held that raise `limited`: four time constants of the default speed loop
/// at this sample period and encoder observer (about 40 ms at 10 kHz).
inline uint32_t limited_window_ticks(const DriveConfig& config) noexcept {
  const Real bandwidth_rad_s = control::default_speed_bandwidth_rad_s(
      control::default_current_bandwidth_rad_s(config.sample_period_s),
      config.encoder_observer_bandwidth_rad_s);
  return static_cast<uint32_t>(std::lround(4 / (bandwidth_rad_s * config.sample_period_s)));
}

class LimitedMonitor {
 public:
  explicit LimitedMonitor(uint32_t window_ticks) noexcept
      : window_(std::max<uint32_t>(window_ticks, 1)), rate_(1.0f / float(window_)) {}

  /// The limit of this tick (none when nothing held the law back, or when not running).
  void update(Limitation now) noexcept {
    // Free, with nothing held and the shares at zero: the update would leave all as it is.
    // The common tick; it then skips the three shares' arithmetic.
    if (now == Limitation::none && quiet_) return;
    // Each reason's share of the recent ticks (a first-order average over the window): the
    // reason reported is the one that dominates, so that ticks alternating between the
    // voltage and the current disk do not flip it.
    bool negligible = now == Limitation::none;
    for (int r = 0; r < kReasons; ++r) {
      const float hit = int(now) == r + 1 ? 1.0f : 0.0f;
      share_[r] += (hit - share_[r]) * rate_;
      negligible = negligible && share_[r] < rate_ * kNegligibleShare;
    }
    if (now != Limitation::none) {
      level_ = std::min(level_ + 1, window_);
      if (level_ == window_ || limited_ != Limitation::none) limited_ = dominant();
    } else if (level_ > 0 && --level_ == 0) {
      limited_ = Limitation::none;
    }
    // A share decays towards zero without reaching it (in float it stops at a denormal near
    // 2^-141 for a window of 400 ticks). Once every share is below a millionth of one tick's
    // weight, none can decide dominant(): the next limited tick adds a whole tick's weight to
    // its reason. They are then zero, and the monitor quiet until a limit comes.
    if (negligible && level_ == 0) {
      for (float& share : share_) share = 0.0f;
      quiet_ = true;
    } else {
      quiet_ = false;
    }
  }
  void reset() noexcept {
    level_ = 0;
    limited_ = Limitation::none;
    for (float& share : share_) share = 0.0f;
    quiet_ = true;
  }
  /// The limitation in force, none if there is none. It clears a window after the last
  /// limited tick, and until then keeps its reason.
  Limitation limited() const noexcept { return limited_; }
  /// Whether the next free tick is skipped: nothing limited, and every share at zero.
  bool quiet() const noexcept { return quiet_; }

 private:
  static constexpr int kReasons = 3;  ///< voltage, current, torque
  /// A share below this many ticks' weight (rate_) counts as none.
  static constexpr float kNegligibleShare = 1e-6f;
  Limitation dominant() const noexcept {
    int best = 0;
    for (int r = 1; r < kReasons; ++r) {
      if (share_[r] > share_[best]) best = r;
    }
    return Limitation(best + 1);
  }

  uint32_t window_;
  float rate_;  ///< 1 / window
  uint32_t level_ = 0;
  Limitation limited_ = Limitation::none;
  float share_[kReasons] = {0.0f, 0.0f, 0.0f};
  /// level_ 0, limited_ none, every share zero: derivable, kept so that a quiet tick tests one
  /// flag rather than three shares.
  bool quiet_ = true;
};

}  // namespace imd::firmware
