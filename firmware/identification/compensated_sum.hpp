#pragma once
/// Kahan-Babuska (Neumaier) compensated summation: sums of tens of thousands of samples in
/// single precision keep their last digits, which the identification needs because it
/// subtracts large, nearly equal sums (docs/identification.md). Tick context.
#include <cmath>

namespace imd::firmware {

template <typename T>
class CompensatedSum {
 public:
  void add(T x) noexcept {
    const T t = sum_ + x;
    compensation_ += std::abs(sum_) >= std::abs(x) ? (sum_ - t) + x : (x - t) + sum_;
    sum_ = t;
  }
  T value() const noexcept { return sum_ + compensation_; }
  void reset() noexcept { sum_ = compensation_ = T(0); }

 private:
  T sum_ = T(0), compensation_ = T(0);
};

}  // namespace imd::firmware
