#include "hal_sim/sim_peripherals.hpp"

#include <chrono>
#include <utility>

namespace imd::sim {

bool SimCan::try_send(const hal::CanFrame& frame) noexcept {
  if (sent_.size() >= kQueueDepth) return false;
  sent_.push_back(frame);
  return true;
}

bool SimCan::try_receive(hal::CanFrame& frame) noexcept {
  if (received_.empty()) return false;
  frame = received_.front();
  received_.pop_front();
  return true;
}

bool SimCan::inject(const hal::CanFrame& frame) {
  if (received_.size() >= kQueueDepth) return false;
  received_.push_back(frame);
  return true;
}

std::deque<hal::CanFrame> SimCan::take_sent() {
  return std::exchange(sent_, {});
}

uint64_t SimTimer::execution_clock_ns() const noexcept {
  return static_cast<uint64_t>(std::chrono::duration_cast<std::chrono::nanoseconds>(
                                   std::chrono::steady_clock::now().time_since_epoch())
                                   .count());
}

void SimTimer::fire() noexcept {
  if (handler_ != nullptr) handler_->on_tick();
  ++ticks_;
}

}  // namespace imd::sim
