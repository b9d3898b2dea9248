#pragma once
/// What a scenario runner reports of a commissioning run ([nameplate], docs/scenarios.md): the
/// simulated time of each step, how it ended, and the motor the drive identified. It watches
/// the drive's status each tick, as a host watches identify_progress.
#include <array>
#include <cstdint>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "control/motor_parameters.hpp"
#include "firmware/drive.hpp"
#include "firmware/protocol/frame_codec.hpp"
#include "firmware/protocol/messages.hpp"

namespace imd::sim {

struct CommissioningReport {
  bool ended = false;
  bool done = false;
  std::string step = "none";                           ///< the last step code's name (done, failed)
  std::string failure = "none";                        ///< identify_failure's name
  std::vector<std::pair<std::string, double>> step_s;  ///< simulated time per step, in order
  double total_s = 0.0;
  std::optional<control::MotorParameters> identified;
  /// Whether J and the friction in `identified` were measured by the rotating step; if not,
  /// they are the record's before, or on a new board the catalogue inertia and no friction.
  bool mechanics_measured = false;
};

class CommissioningWatch {
 public:
  explicit CommissioningWatch(double period_s) : period_s_(period_s) {}

  /// After each tick (and service). True once the commissioning has ended and its result,
  /// if any, is the drive's record: the run can stop.
  template <typename T>
  bool after_tick(const firmware::Drive<T>& drive) {
    const firmware::DriveStatus& status = drive.status();
    if (drive.state() == firmware::DriveState::identifying) {
      started_ = true;
      if (status.identify_step < ticks_.size()) ++ticks_[status.identify_step];
      // The end (done, failed) is reported below, not as a step of its own.
      const bool end = status.identify_step == 4 || status.identify_step == 5;
      if (status.identify_step != last_step_ && !end) order_.push_back(status.identify_step);
      last_step_ = status.identify_step;
      return false;
    }
    if (!started_) return false;
    // Ended: a done run is finished once the drive runs on the new record (idle).
    const bool done = status.identify_step == 4;
    if (done && drive.state() != firmware::DriveState::idle && ++settle_ticks_ < 10'000) {
      return false;
    }
    report_.ended = true;
    report_.done = done && drive.state() == firmware::DriveState::idle;
    report_.step = name(firmware::protocol::kIdentifyProgressSignals[0], status.identify_step);
    report_.failure =
        name(firmware::protocol::kIdentifyProgressSignals[2], status.identify_failure);
    finish();
    if (report_.done) report_.identified = drive.motor();
    return true;
  }

  /// The time of each step so far (a run cut short reports what it did).
  void finish() {
    report_.step_s.clear();
    report_.total_s = 0.0;
    for (const uint8_t step : order_) {
      report_.step_s.emplace_back(name(firmware::protocol::kIdentifyProgressSignals[0], step),
                                  double(ticks_[step]) * period_s_);
      report_.total_s += double(ticks_[step]) * period_s_;
    }
  }

  /// Marks the mechanics measured when the rotating step ran to its end.
  void mechanics_measured(bool rotated) {
    report_.mechanics_measured =
        report_.done && rotated && report_.failure == "none" && report_.identified.has_value();
  }

  /// Whether a commissioning was seen at all, and how it ended.
  const CommissioningReport& report() const noexcept { return report_; }
  CommissioningReport& report() noexcept { return report_; }

 private:
  static std::string name(const firmware::protocol::Signal& signal, int64_t raw) {
    const char* n = firmware::protocol::value_name(signal, raw);
    return n != nullptr ? n : std::to_string(raw);
  }

  double period_s_;
  bool started_ = false;
  uint8_t last_step_ = 0xFF;
  int settle_ticks_ = 0;
  std::array<uint64_t, 16> ticks_{};
  std::vector<uint8_t> order_;
  CommissioningReport report_;
};

}  // namespace imd::sim
