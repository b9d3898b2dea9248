#include "hal_sim/sim_peripherals.hpp"

#include "hal_sim/host_clock.hpp"

namespace imd::sim {

bool SimCan::try_send(const hal::CanFrame& frame) noexcept {
  return sent_.push(frame);
}

bool SimCan::try_receive(hal::CanFrame& frame) noexcept {
  return received_.pop(frame);
}

bool SimCan::inject(const hal::CanFrame& frame) noexcept {
  if (silenced_) {
    ++dropped_;
    return false;
  }
  return received_.push(frame);
}

uint32_t SimTimer::execution_counts() const noexcept {
  const uint64_t host_ns = host_clock_ns();
  uint64_t stall_ns = 0;
  if (in_fire_ && reads_in_fire_++ > 0) stall_ns = stall_ns_;
  return uint32_t(host_ns + stolen_ns_ + stall_ns);
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
