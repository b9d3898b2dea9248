#include "hal/linux/realtime_timer.hpp"

#include <fcntl.h>
#include <sched.h>
#include <unistd.h>
#include <sys/mman.h>
#include <time.h>

#include <cerrno>
#include <cstring>

namespace imd::hal {
namespace {

constexpr uint64_t kNsPerSecond = 1000000000;

timespec to_timespec(uint64_t ns) noexcept {
  timespec t{};
  t.tv_sec = static_cast<time_t>(ns / kNsPerSecond);
  t.tv_nsec = static_cast<long>(ns % kNsPerSecond);
  return t;
}

}  // namespace

uint64_t monotonic_ns() noexcept {
  timespec now{};
  ::clock_gettime(CLOCK_MONOTONIC, &now);
  return uint64_t(now.tv_sec) * kNsPerSecond + uint64_t(now.tv_nsec);
}

std::string lock_memory() {
  if (::mlockall(MCL_CURRENT | MCL_FUTURE) == 0) return {};
  return std::string("mlockall: ") + std::strerror(errno) +
         ": memory is not locked, a page fault may delay a tick (run as root, or raise "
         "RLIMIT_MEMLOCK)";
}

CpuIdleLatencyRequest::CpuIdleLatencyRequest() {
  fd_ = ::open("/dev/cpu_dma_latency", O_WRONLY | O_CLOEXEC);
  const int32_t zero_us = 0;
  if (fd_ < 0 || ::write(fd_, &zero_us, sizeof zero_us) != sizeof zero_us) {
    warning_ = std::string("/dev/cpu_dma_latency: ") + std::strerror(errno) +
               ": the CPUs may enter deep idle states, which delays the loop's wake-ups";
  }
}

CpuIdleLatencyRequest::~CpuIdleLatencyRequest() {
  if (fd_ >= 0) ::close(fd_);  // closing ends the request
}

void RealtimeTimer::start(TickHandler& handler) noexcept {
  if (running_.load()) return;
  stop_requested_.store(false);
  std::atomic<bool> configured{false};
  try {
    thread_ = std::thread([this, &handler, &configured] {
      configured.wait(false);  // until the priority and affinity below are set
      loop(handler);
    });
  } catch (const std::system_error& e) {
    warning_ = std::string("cannot start the control thread: ") + e.what();
    return;
  }
  running_.store(true);
  const pthread_t native = thread_.native_handle();
  if (options_.fifo_priority > 0) {
    sched_param param{};
    param.sched_priority = options_.fifo_priority;
    const int error = ::pthread_setschedparam(native, SCHED_FIFO, &param);
    realtime_ = error == 0;
    if (!realtime_) {
      warning_ = std::string("SCHED_FIFO priority ") + std::to_string(options_.fifo_priority) +
                 " refused (" + std::strerror(error) +
                 "): the loop runs under the normal scheduler and other processes delay its "
                 "ticks (run as root or with CAP_SYS_NICE)";
    }
  }
  if (options_.cpu >= 0) {
    cpu_set_t cpus;
    CPU_ZERO(&cpus);
    CPU_SET(options_.cpu, &cpus);
    const int error = ::pthread_setaffinity_np(native, sizeof cpus, &cpus);
    if (error != 0) {
      if (!warning_.empty()) warning_ += "; ";
      warning_ += "cannot pin the loop to CPU " + std::to_string(options_.cpu) + " (" +
                  std::strerror(error) + ")";
    }
  }
  configured.store(true);
  configured.notify_one();
  // The thread may still read `configured` after notify: wait until it has passed the wait.
  while (!loop_entered_.load()) std::this_thread::yield();
}

void RealtimeTimer::stop() noexcept {
  stop_requested_.store(true);
  if (thread_.joinable()) thread_.join();
  running_.store(false);
}

void RealtimeTimer::loop(TickHandler& handler) noexcept {
  loop_entered_.store(true);
  const uint64_t period = options_.period_ns;
  uint64_t deadline = monotonic_ns() + period;
  while (!stop_requested_.load(std::memory_order_relaxed)) {
    const timespec wake = to_timespec(deadline);
    while (::clock_nanosleep(CLOCK_MONOTONIC, TIMER_ABSTIME, &wake, nullptr) == EINTR) {
    }
    const uint64_t woke = monotonic_ns();
    wakeup_.record(int64_t(woke - deadline));
    handler.on_tick();
    const uint64_t done = monotonic_ns();
    execution_.record(int64_t(done - woke));
    ticks_.store(ticks_.load(std::memory_order_relaxed) + 1, std::memory_order_relaxed);
    deadline += period;
    if (done >= deadline) {  // the next deadline has passed: skip to the first one ahead
      const uint64_t skipped = (done - deadline) / period + 1;
      deadline += skipped * period;
      missed_.fetch_add(skipped, std::memory_order_relaxed);
    }
  }
}

}  // namespace imd::hal
