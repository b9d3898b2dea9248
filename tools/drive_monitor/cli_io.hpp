#pragma once
/// What drive_monitor's subcommands share on a live bus: the stop signals, waiting for frames
/// with a deadline, error messages and exit codes, and the seconds validator of the CLI.
#include <CLI/CLI.hpp>

#include <chrono>
#include <csignal>
#include <string>

#include "tools/drive_monitor/live_bus.hpp"

namespace imd::monitor::cli {

using Clock = std::chrono::steady_clock;

inline constexpr int kExitOutputError = 1;
inline constexpr int kExitBadInput = 2;
inline constexpr int kExitRejected = 3;
inline constexpr int kExitNoAnswer = 4;

/// Set by SIGINT or SIGTERM while a StopSignals lives.
extern volatile std::sig_atomic_t g_stop;

/// SIGINT and SIGTERM set g_stop from now on (they stay unblocked).
void set_stop_on_signals();

/// SIGINT and SIGTERM set g_stop. While an object lives they are blocked except inside
/// wait_readable, whose ppoll unblocks them atomically: a signal that lands between a check of
/// g_stop and the wait still ends the wait at once, not at its timeout (1/F s can be minutes at
/// a low --repeat-hz).
class StopSignals {
 public:
  StopSignals();
  ~StopSignals();
  StopSignals(const StopSignals&) = delete;
  StopSignals& operator=(const StopSignals&) = delete;

 private:
  sigset_t previous_{};
};

std::string seconds_text(double seconds);
/// Prints "drive_monitor: MESSAGE" on standard error and returns `code`.
int fail(const std::string& message, int code = kExitBadInput);

/// A duration in (0, 1e7] s; CLI11's PositiveNumber lets NaN through.
extern const CLI::Validator kSeconds;

/// Waits until the bus has data or `deadline` passes (or a signal arrives). ppoll rather
/// than poll for its nanosecond timeout (poll's milliseconds would make a wait up to a whole
/// period late at 1000 Hz) and its atomic signal mask (StopSignals).
void wait_readable(const LiveBus& bus, Clock::time_point deadline);

/// Receives until `accept(frame)` returns true or `wait_s` passes.
template <typename Accept>
bool receive_until(LiveBus& bus, double wait_s, Accept accept) {
  const Clock::time_point deadline = Clock::now() + std::chrono::duration_cast<Clock::duration>(
                                                        std::chrono::duration<double>(wait_s));
  hal::CanFrame frame;
  while (g_stop == 0) {
    while (bus.try_receive(frame)) {
      if (accept(frame)) return true;
    }
    if (Clock::now() >= deadline || bus.lost()) return false;
    wait_readable(bus, deadline);
  }
  return false;
}

}  // namespace imd::monitor::cli
