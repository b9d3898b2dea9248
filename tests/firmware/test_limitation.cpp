// The `limited` report (firmware/limitation.hpp): the persistence of the monitor, its window
// rule, and which limit an input on the edge of the feasible set presses against.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>

#include "control/voltage_fed_model.hpp"
#include "firmware/drive_config.hpp"
#include "firmware/limitation.hpp"
#include "firmware/paper_motor.hpp"
#include "firmware/stages/input_limits.hpp"

namespace imd::firmware {
namespace {

constexpr uint32_t kWindow = 400;

TEST(LimitedMonitor, RaisesAfterAWindowOfLimitedTicksAndClearsAfterAsManyFreeOnes) {
  LimitedMonitor m(kWindow);
  for (uint32_t k = 1; k < kWindow; ++k) {
    m.update(Limitation::voltage);
    ASSERT_EQ(m.limited(), Limitation::none) << k;
  }
  m.update(Limitation::voltage);
  EXPECT_EQ(m.limited(), Limitation::voltage);
  // While raised, the reason is the dominant one: a tick of current does not flip it, a
  // window of current does.
  m.update(Limitation::current);
  EXPECT_EQ(m.limited(), Limitation::voltage);
  for (uint32_t k = 0; k < kWindow; ++k) m.update(Limitation::current);
  EXPECT_EQ(m.limited(), Limitation::current);
  for (uint32_t k = 1; k < kWindow; ++k) {
    m.update(Limitation::none);
    ASSERT_EQ(m.limited(), Limitation::current) << k;
  }
  m.update(Limitation::none);
  EXPECT_EQ(m.limited(), Limitation::none);
}

TEST(LimitedMonitor, AlternatingReasonsDoNotFlipTheReport) {
  // Ticks alternating between the voltage and the current disk, two of voltage for one of
  // current: raised, and voltage throughout.
  LimitedMonitor m(kWindow);
  int flips = 0;
  Limitation last = Limitation::none;
  for (int k = 0; k < 20 * int(kWindow); ++k) {
    m.update(k % 3 == 2 ? Limitation::current : Limitation::voltage);
    if (m.limited() != last && last != Limitation::none) ++flips;
    last = m.limited();
  }
  EXPECT_EQ(m.limited(), Limitation::voltage);
  EXPECT_EQ(flips, 0);
}

TEST(LimitedMonitor, IgnoresALimitTouchedInLessThanHalfOfTheTicks) {
  // The sliding-mode law steps onto the voltage disk now and then (under 5 % of the ticks on
  // the realistic profile); even 49 % never fills the count.
  LimitedMonitor m(kWindow);
  for (int k = 0; k < 100 * int(kWindow); ++k) {
    m.update(k % 100 < 49 ? Limitation::voltage : Limitation::none);
    ASSERT_EQ(m.limited(), Limitation::none) << k;
  }
  m.reset();
  for (uint32_t k = 0; k < 2 * kWindow; ++k) m.update(Limitation::torque);
  EXPECT_EQ(m.limited(), Limitation::torque);
  m.reset();
  EXPECT_EQ(m.limited(), Limitation::none);
}

/// The monitor as it was before it skipped its quiet ticks: every share updated every tick.
class UpdatedEveryTick {
 public:
  explicit UpdatedEveryTick(uint32_t window) : window_(window), rate_(1.0f / float(window)) {}
  void update(Limitation now) {
    for (int r = 0; r < 3; ++r) {
      share_[r] += ((int(now) == r + 1 ? 1.0f : 0.0f) - share_[r]) * rate_;
    }
    if (now != Limitation::none) {
      level_ = std::min(level_ + 1, window_);
      if (level_ == window_ || limited_ != Limitation::none) {
        int best = 0;
        for (int r = 1; r < 3; ++r) best = share_[r] > share_[best] ? r : best;
        limited_ = Limitation(best + 1);
      }
    } else if (level_ > 0 && --level_ == 0) {
      limited_ = Limitation::none;
    }
  }
  Limitation limited() const { return limited_; }

 private:
  uint32_t window_;
  float rate_;
  uint32_t level_ = 0;
  Limitation limited_ = Limitation::none;
  float share_[3] = {0.0f, 0.0f, 0.0f};
};

TEST(LimitedMonitor, SkippingQuietTicksReportsWhatUpdatingEveryTickReports) {
  // Bursts of limits (each reason, mixed, of random lengths and densities) between free
  // stretches long enough for the shares to fall to nothing (up to 40 windows), 2 million
  // ticks: the same report every tick. The skip leaves out only ticks whose update changes
  // nothing but shares below a millionth of a tick's weight.
  std::mt19937 rng(7);
  for (const uint32_t window : {4u, 127u, kWindow, 800u}) {
    LimitedMonitor skipping(window);
    UpdatedEveryTick every(window);
    uint64_t k = 0, limited_ticks = 0, quiet_stretches = 0;
    while (k < 2'000'000) {
      const uint32_t burst = std::uniform_int_distribution<uint32_t>(1, 4 * window)(rng);
      const float density = std::uniform_real_distribution<float>(0.2f, 1.0f)(rng);
      const int reasons = std::uniform_int_distribution<int>(1, 3)(rng);
      for (uint32_t i = 0; i < burst; ++i, ++k) {
        const bool hit = std::uniform_real_distribution<float>(0, 1)(rng) < density;
        const Limitation now =
            hit ? Limitation(std::uniform_int_distribution<int>(1, reasons)(rng))
                : Limitation::none;
        skipping.update(now);
        every.update(now);
        ASSERT_EQ(skipping.limited(), every.limited()) << "window " << window << " tick " << k;
        limited_ticks += skipping.limited() != Limitation::none;
      }
      const uint32_t free = std::uniform_int_distribution<uint32_t>(1, 40 * window)(rng);
      for (uint32_t i = 0; i < free; ++i, ++k) {
        skipping.update(Limitation::none);
        every.update(Limitation::none);
        ASSERT_EQ(skipping.limited(), every.limited()) << "window " << window << " tick " << k;
      }
      quiet_stretches += skipping.quiet();
    }
    EXPECT_GT(limited_ticks, 0u) << window;  // the comparison saw the report raised
    EXPECT_GT(quiet_stretches, 0u) << window;  // and ticks skipped
  }
}

TEST(LimitedMonitor, WindowIsFourTimeConstantsOfTheDefaultSpeedLoop) {
  DriveConfig c;
  // 10 kHz with the 400 rad/s encoder observer: speed bandwidth min(w_c/10, 400/4) = 100 rad/s,
  // 4/100 s = 400 ticks.
  c.sample_period_s = 1e-4;
  c.encoder_observer_bandwidth_rad_s = 400.0;
  EXPECT_EQ(limited_window_ticks(c), 400u);
  // At 1 kHz the current bandwidth (w_c = 2 pi 1000/20 = 314 rad/s) limits the speed loop to
  // 31.4 rad/s: 4/31.4 s = 127 ticks.
  c.sample_period_s = 1e-3;
  EXPECT_EQ(limited_window_ticks(c), 127u);
}

TEST(InputLimitsBinding, NamesTheDiskTheInputIsNearerToLeaving) {
  const control::MotorParameters motor = test::paper_motor();
  const auto c = control::discretize_voltage_fed(motor, 1e-4);
  InputLimitsConfig config;
  config.i_max_A = 6.0;
  const InputLimits<double> limits(motor, c, config);
  control::RotorFrameState<double> x;
  x.flux_r_AB_Wb = {0.45, 0.0};
  // 5.86 A, which the free response brings to 5.64 A, just under the 5.7 A limit: the 170 V
  // the voltage allows move the next current by up to 0.3 A, so both disks bound the input.
  x.i_s_AB_A = {5.2, 2.7};
  x.omega_mech_rad_s = 300.0;
  const double v_bus_V = 311.0;
  const control::InputDisk<double> feasible = limits.feasible(x, v_bus_V);
  // The feasible disk is the largest inside both limits: it touches the voltage disk on the
  // side away from the voltage disk's centre, and the current disk on the side away from
  // the current disk's centre. At each touching point that limit is fully used and the other
  // is not: binding must name it.
  InputLimitsConfig voltage_only;
  const control::InputDisk<double> v_disk =
      InputLimits<double>(motor, c, voltage_only).feasible(x, v_bus_V);
  InputLimitsConfig current_only;
  current_only.voltage_limited = false;
  current_only.i_max_A = 6.0;
  const control::InputDisk<double> i_disk =
      InputLimits<double>(motor, c, current_only).feasible(x, v_bus_V);
  ASSERT_LT(feasible.radius_V, v_disk.radius_V);  // both bound it: a lens, not one disk
  ASSERT_LT(feasible.radius_V, i_disk.radius_V);
  const auto touching = [&](const control::InputDisk<double>& limit) {
    const control::Vec2<double> away = (feasible.center_V - limit.center_V).normalized();
    return control::Vec2<double>(feasible.center_V + feasible.radius_V * away);
  };
  EXPECT_EQ(limits.binding(x, v_bus_V, touching(v_disk)), Limitation::voltage);
  EXPECT_EQ(limits.binding(x, v_bus_V, touching(i_disk)), Limitation::current);
  // Without a current limit, only the voltage can bind, and the reverse.
  InputLimitsConfig no_current;
  EXPECT_EQ(InputLimits<double>(motor, c, no_current).binding(x, v_bus_V, feasible.center_V),
            Limitation::voltage);
  InputLimitsConfig no_voltage;
  no_voltage.voltage_limited = false;
  no_voltage.i_max_A = 6.0;
  EXPECT_EQ(InputLimits<double>(motor, c, no_voltage).binding(x, v_bus_V, feasible.center_V),
            Limitation::current);
}

}  // namespace
}  // namespace imd::firmware
