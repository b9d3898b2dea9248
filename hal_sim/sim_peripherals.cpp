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
  if (silenced_) {
    ++dropped_;
    return false;
  }
  if (received_.size() >= kQueueDepth) return false;
  received_.push_back(frame);
  return true;
}

std::deque<hal::CanFrame> SimCan::take_sent() {
  return std::exchange(sent_, {});
}

void SimCan::take_sent(std::vector<hal::CanFrame>& out) {
  out.assign(sent_.begin(), sent_.end());
  sent_.clear();
}

uint64_t SimTimer::execution_clock_ns() const noexcept {
  const auto host_ns =
      static_cast<uint64_t>(std::chrono::duration_cast<std::chrono::nanoseconds>(
                                std::chrono::steady_clock::now().time_since_epoch())
                                .count());
  uint64_t stall_ns = 0;
  if (in_fire_ && reads_in_fire_++ > 0) stall_ns = stall_ns_;
  return host_ns + stolen_ns_ + stall_ns;
}

void SimTimer::fire() noexcept {
  in_fire_ = true;
  reads_in_fire_ = 0;
  if (handler_ != nullptr) handler_->on_tick();
  in_fire_ = false;
  stolen_ns_ += stall_ns_;  // the stolen time has passed for every later read
  ++ticks_;
}

}  // namespace imd::sim
