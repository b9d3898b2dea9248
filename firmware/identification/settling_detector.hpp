#pragma once
/// When a level has settled, without knowing its time constant. After a current step the
/// voltage the current loop needs decays as A exp(-t/tau_r) (the rotor flux building up) once
/// the current has arrived at its new level. The detector splits the windows since the arrival
/// into three equal segments of L windows; their means S1, S2, S3 give
///   tau = L / ln((S1 - S2) / (S2 - S3)),
/// each segment averaging the noise over many samples (a fit on single windows fails on a
/// large motor, whose decay is a few times its noise). The level is settled once the segments
/// span 9 tau (the tail left is e^-9 of the step), or once the first difference is lost in the
/// noise (everything decayed within the first segment). The noise is estimated from second
/// differences of consecutive windows, which a slow decay hardly reaches. The windows are kept as
/// sums in buckets that double in length when full: no heap, bounded memory. Tick context.
#include <array>
#include <cmath>
#include <cstdint>

namespace imd::firmware {

template <typename T>
class SettlingDetector {
 public:
  static constexpr int kBuckets = 48;     ///< a multiple of 3
  static constexpr int kMinWindows = 12;  ///< at least four windows per segment

  /// The next window's mean; `arrived`: the current is at its new level. True once settled
  /// (and from then on).
  bool on_window(T mean, bool arrived) noexcept {
    ++windows_;
    if (settled_) return true;
    if (!arrived && count_ == 0) return false;  // the current loop's own transient
    if (count_ > 1) {  // the noise, from second differences: a slow decay hardly shows in them
      const T dd = mean - T(2) * previous_ + before_previous_;
      square_differences_ += dd * dd;
      ++differences_;
    }
    before_previous_ = previous_;
    previous_ = mean;
    ++count_;
    bucket_sum_ += mean;
    if (++bucket_fill_ < bucket_windows_) return false;
    buckets_[full_++] = bucket_sum_;
    bucket_sum_ = T(0);
    bucket_fill_ = 0;
    if (full_ % 3 == 0 && count_ >= kMinWindows) settled_ = judge();
    if (full_ == kBuckets) {  // merge pairs: buckets twice as long
      for (int i = 0; i < kBuckets / 2; ++i) buckets_[i] = buckets_[2 * i] + buckets_[2 * i + 1];
      full_ = kBuckets / 2;
      bucket_windows_ *= 2;
    }
    return settled_;
  }
  /// The time constant in windows, as last measured (0 if never).
  T tau_windows() const noexcept { return tau_windows_; }
  uint32_t windows() const noexcept { return windows_; }
  /// A rough share of the settling done, 0..1 (for the progress report).
  T progress() const noexcept {
    if (settled_) return T(1);
    if (tau_windows_ <= T(0)) return T(0);
    const T needed = T(9) * tau_windows_;
    return std::fmin(T(0.99), T(count_) / needed);
  }

 private:
  bool judge() noexcept {
    const int per = full_ / 3;
    T s[3] = {T(0), T(0), T(0)};
    for (int k = 0; k < 3; ++k) {
      for (int i = 0; i < per; ++i) s[k] += buckets_[k * per + i];
    }
    const T windows_per_segment = T(per * bucket_windows_);
    for (T& x : s) x /= windows_per_segment;
    const T d1 = s[0] - s[1], d2 = s[1] - s[2];
    // A segment mean's noise is that of a window over sqrt(L); a difference of two, sqrt(2)
    // more. Three of those is "significant".
    // A second difference of independent windows has six times a window's variance.
    const T window_noise =
        differences_ > 0 ? std::sqrt(square_differences_ / T(6 * differences_)) : T(0);
    const T difference_noise = window_noise * std::sqrt(T(2) / windows_per_segment);
    const T significant = T(3) * difference_noise;
    if (std::abs(d1) <= significant) {  // decayed within the first segment, or no decay at all
      tau_windows_ = windows_per_segment / T(3);
      return true;
    }
    if (std::abs(d2) <= significant || d2 * d1 <= T(0) || std::abs(d2) >= std::abs(d1)) {
      // The second difference is noise: the decay took under a segment, ~L/3 for tau; or the
      // segments are still too short to tell. Go on unless the segments are long already.
      tau_windows_ = windows_per_segment / T(3);
      return std::abs(d2) <= significant;
    }
    tau_windows_ = windows_per_segment / std::log(d1 / d2);
    return windows_per_segment >= T(3) * tau_windows_;
  }

  std::array<T, kBuckets> buckets_{};
  int full_ = 0, bucket_windows_ = 1, bucket_fill_ = 0;
  T bucket_sum_ = T(0), previous_ = T(0), before_previous_ = T(0);
  T square_differences_ = T(0), tau_windows_ = T(0);
  uint32_t windows_ = 0, count_ = 0, differences_ = 0;
  bool settled_ = false;
};

}  // namespace imd::firmware
