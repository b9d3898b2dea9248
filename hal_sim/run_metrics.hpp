#pragma once
/// The tracking metrics of a scenario run (docs/scenarios.md) over t > settle_s, from the
/// plant's true state and the drive's record: RMS and largest speed and flux errors, the RMS
/// load-estimate error, the peak current and the share of saturated ticks. No heap: drive_sim
/// and the processor-in-the-loop image compute them with this same code.
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>

namespace imd::sim {

/// One tick's errors against the plant's true state.
struct MetricsSample {
  double t_s = 0.0;
  bool measuring = true;  ///< counted (after settle_s; over CAN, while running)
  double speed_err_rad_s = 0.0;
  double flux2_err_Wb2 = 0.0;  ///< of the controlled flux (rotor or stator)
  double load_err_Nm = 0.0;
  double current_A = 0.0;  ///< |i_s|
  bool saturated = false;
};

class RunMetrics {
 public:
  explicit RunMetrics(double settle_s) noexcept : settle_s_(settle_s) {}

  void add(const MetricsSample& s) noexcept {
    i_peak_total_A_ = std::max(i_peak_total_A_, s.current_A);
    if (!(s.t_s > settle_s_ && s.measuring)) return;
    speed_sq_ += s.speed_err_rad_s * s.speed_err_rad_s;
    flux_sq_ += s.flux2_err_Wb2 * s.flux2_err_Wb2;
    load_sq_ += s.load_err_Nm * s.load_err_Nm;
    speed_max_ = std::max(speed_max_, std::abs(s.speed_err_rad_s));
    flux_max_ = std::max(flux_max_, std::abs(s.flux2_err_Wb2));
    i_peak_A_ = std::max(i_peak_A_, s.current_A);
    saturated_ += s.saturated ? 1 : 0;
    ++measured_;
  }

  /// NaN when nothing was measured (a run that ended before settle_s).
  double speed_rms_err_rad_s() const noexcept { return std::sqrt(speed_sq_ / n()); }
  double speed_max_err_rad_s() const noexcept { return measured_ ? speed_max_ : nan(); }
  double flux2_rms_err_Wb2() const noexcept { return std::sqrt(flux_sq_ / n()); }
  double flux2_max_err_Wb2() const noexcept { return measured_ ? flux_max_ : nan(); }
  double load_est_rms_err_Nm() const noexcept { return std::sqrt(load_sq_ / n()); }
  double i_peak_A() const noexcept { return measured_ ? i_peak_A_ : nan(); }
  double i_peak_total_A() const noexcept { return i_peak_total_A_; }
  double saturated_fraction() const noexcept { return double(saturated_) / n(); }
  uint64_t measured_ticks() const noexcept { return measured_; }

 private:
  static double nan() noexcept { return std::numeric_limits<double>::quiet_NaN(); }
  double n() const noexcept { return measured_ > 0 ? double(measured_) : nan(); }

  double settle_s_;
  double speed_sq_ = 0, flux_sq_ = 0, load_sq_ = 0;
  double speed_max_ = 0, flux_max_ = 0, i_peak_A_ = 0, i_peak_total_A_ = 0;
  uint64_t saturated_ = 0, measured_ = 0;
};

}  // namespace imd::sim
