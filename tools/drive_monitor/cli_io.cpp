#include "tools/drive_monitor/cli_io.hpp"

#include <poll.h>

#include <algorithm>
#include <cerrno>
#include <cstdlib>
#include <iostream>
#include <sstream>

namespace imd::monitor::cli {
namespace {

/// The signal mask wait_readable's ppoll waits with; nullptr: the present one.
const sigset_t* g_wait_mask = nullptr;

extern "C" void on_signal(int) {
  g_stop = 1;
}

}  // namespace

volatile std::sig_atomic_t g_stop = 0;

void set_stop_on_signals() {
  std::signal(SIGINT, on_signal);
  std::signal(SIGTERM, on_signal);
}

StopSignals::StopSignals() {
  struct sigaction action {};
  action.sa_handler = on_signal;
  sigemptyset(&action.sa_mask);
  ::sigaction(SIGINT, &action, nullptr);
  ::sigaction(SIGTERM, &action, nullptr);
  sigset_t stop;
  sigemptyset(&stop);
  sigaddset(&stop, SIGINT);
  sigaddset(&stop, SIGTERM);
  ::sigprocmask(SIG_BLOCK, &stop, &previous_);
  g_wait_mask = &previous_;
}

StopSignals::~StopSignals() {
  g_wait_mask = nullptr;
  ::sigprocmask(SIG_SETMASK, &previous_, nullptr);
}

std::string seconds_text(double seconds) {
  std::ostringstream text;
  text << seconds;
  return text.str();
}

int fail(const std::string& message, int code) {
  std::cerr << "drive_monitor: " << message << '\n';
  return code;
}

const CLI::Validator kSeconds(
    [](std::string& text) -> std::string {
      char* end = nullptr;
      const double value = std::strtod(text.c_str(), &end);
      if (end == text.c_str() || *end != '\0') return "must be a number, got " + text;
      if (!(value > 0.0 && value <= 1e7)) return "must be a time in (0, 1e7] s, got " + text;
      return {};
    },
    "SECONDS");

void wait_readable(const LiveBus& bus, Clock::time_point deadline) {
  const int64_t left_ns = std::max<int64_t>(
      0, std::chrono::duration_cast<std::chrono::nanoseconds>(deadline - Clock::now()).count());
  const timespec timeout{static_cast<time_t>(left_ns / 1'000'000'000),
                         static_cast<long>(left_ns % 1'000'000'000)};
  pollfd fd{bus.native_handle(), bus.poll_events(), 0};
  ::ppoll(&fd, 1, &timeout, g_wait_mask);
}

}  // namespace imd::monitor::cli
