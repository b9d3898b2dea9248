#include "hal/linux/queued_can_bus.hpp"

#include <poll.h>

#include <chrono>

namespace imd::hal {
namespace {

constexpr int kPollTimeout_ms = 1;
constexpr int kStopFlushTimeout_ms = 100;

}  // namespace

std::unique_ptr<QueuedCanBus> QueuedCanBus::open(const std::string& iface, std::string& error,
                                                 const std::vector<CanIdFilter>& filters) {
  std::unique_ptr<SocketCanBus> socket = SocketCanBus::open(iface, error, filters);
  if (!socket) return nullptr;
  return std::unique_ptr<QueuedCanBus>(new QueuedCanBus(std::move(socket)));
}

QueuedCanBus::QueuedCanBus(std::unique_ptr<SocketCanBus> socket) : socket_(std::move(socket)) {
  io_ = std::thread([this] { run_io(); });
}

QueuedCanBus::~QueuedCanBus() {
  flush(kStopFlushTimeout_ms);
  stop_.store(true);
  io_.join();
}

void QueuedCanBus::run_io() noexcept {
  pollfd watch{socket_->native_handle(), POLLIN, 0};
  while (!stop_.load(std::memory_order_relaxed)) {
    // Waiting for POLLOUT as well would spin while the controller is bus-off; a frame the
    // socket refused is retried on the next wake-up instead.
    ::poll(&watch, 1, kPollTimeout_ms);
    exchange();
  }
}

void QueuedCanBus::exchange() noexcept {
  CanFrame frame;
  while (socket_->try_receive(frame)) {
    if (rx_.try_push(frame)) {
      received_.fetch_add(1, std::memory_order_relaxed);
    } else {
      rx_dropped_.fetch_add(1, std::memory_order_relaxed);
    }
  }
  for (const CanFrame* next = tx_.front(); next != nullptr; next = tx_.front()) {
    if (!socket_->try_send(*next)) {
      tx_retries_.fetch_add(1, std::memory_order_relaxed);
      break;
    }
    tx_.pop();
    sent_.fetch_add(1, std::memory_order_relaxed);
  }
  const CanErrorState& errors = socket_->errors();
  bus_off_.store(errors.bus_off, std::memory_order_relaxed);
  error_frames_.store(errors.error_frames, std::memory_order_relaxed);
  bus_off_events_.store(errors.bus_off_events, std::memory_order_relaxed);
  last_error_class_.store(errors.last_error_class, std::memory_order_relaxed);
}

bool QueuedCanBus::flush(int timeout_ms) noexcept {
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::milliseconds(timeout_ms);
  while (tx_.size() > 0) {
    if (std::chrono::steady_clock::now() >= deadline) return false;
    std::this_thread::sleep_for(std::chrono::microseconds(200));
  }
  return true;
}

QueuedCanCounters QueuedCanBus::counters() const noexcept {
  QueuedCanCounters c;
  c.sent = sent_.load();
  c.received = received_.load();
  c.rx_dropped = rx_dropped_.load();
  c.tx_retries = tx_retries_.load();
  c.error_frames = error_frames_.load();
  c.bus_off_events = bus_off_events_.load();
  c.last_error_class = last_error_class_.load();
  return c;
}

}  // namespace imd::hal
