#pragma once
/// The drive's state machine:
///   calibrating -> idle -> magnetizing -> running -> stopping -> idle
///   calibrating -> unconfigured -> idle: no motor record, until a valid one is written
///   idle -> unconfigured -> idle: a parameter write, while the model is rebuilt
///   idle or unconfigured -> identifying -> unconfigured: the commissioning run (then idle once
///   its record is applied; back to idle or unconfigured if it fails or is disabled)
///   any state -> fault -> idle (only by clear_faults; to calibrating if the fault came first,
///   to unconfigured without a motor record)
///   magnetizing, running or stopping -> idle by shutdown only (the program ends, PWM off)
/// Every transition is checked against this graph, counted, and kept in a short log that the
/// telemetry reports as state_change frames. No heap; tick context.
#include <array>
#include <cstdint>

#include "firmware/drive_state.hpp"

namespace imd::firmware {

struct Transition {
  uint64_t tick = 0;
  DriveState from = DriveState::calibrating, to = DriveState::calibrating;
  TransitionReason reason = TransitionReason::calibrated;
};

class StateMachine {
 public:
  static constexpr std::size_t kLogDepth = 16;

  DriveState state() const noexcept { return state_; }

  /// Moves to `to` if the graph allows it; false (and nothing changes) otherwise.
  bool go(DriveState to, TransitionReason reason, uint64_t tick) noexcept {
    if (!allowed(state_, to, reason)) return false;
    log_[count_ % kLogDepth] = {tick, state_, to, reason};
    ++count_;
    ++entered_[static_cast<int>(to)];
    state_ = to;
    return true;
  }

  static constexpr bool allowed(DriveState from, DriveState to,
                                TransitionReason reason) noexcept {
    using S = DriveState;
    if (reason == TransitionReason::shutdown) {
      return to == S::idle && (from == S::magnetizing || from == S::running || from == S::stopping);
    }
    if (to == S::fault) return from != S::fault;
    switch (from) {
      case S::calibrating:
        return to == S::idle || to == S::unconfigured;
      case S::idle:
        return to == S::magnetizing || to == S::unconfigured || to == S::identifying;
      case S::unconfigured:
        return to == S::idle || to == S::identifying;
      case S::identifying:
        return to == S::unconfigured || to == S::idle;
      case S::magnetizing:
        return to == S::running || to == S::idle;
      case S::running:
        return to == S::stopping;
      case S::stopping:
        return to == S::idle;
      case S::fault:
        return to == S::idle || to == S::calibrating || to == S::unconfigured;
    }
    return false;
  }

  /// Transitions since start-up.
  uint32_t count() const noexcept { return count_; }
  /// How often a state was entered.
  uint32_t entered(DriveState s) const noexcept { return entered_[static_cast<int>(s)]; }
  /// Transition number n (0-based) if it is still in the log.
  bool logged(uint32_t n, Transition& out) const noexcept {
    if (n >= count_ || count_ - n > kLogDepth) return false;
    out = log_[n % kLogDepth];
    return true;
  }

 private:
  DriveState state_ = DriveState::calibrating;
  uint32_t count_ = 0;
  std::array<uint32_t, kDriveStateCount> entered_{};
  std::array<Transition, kLogDepth> log_{};
};

}  // namespace imd::firmware
