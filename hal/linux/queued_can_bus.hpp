#pragma once
/// hal::CanBus for the real-time tick on Linux: the tick only touches two lock-free rings, and
/// an I/O thread moves frames between them and a SocketCAN socket. No system call, lock or
/// allocation happens in the tick.
///   tick --try_send--> tx ring --I/O thread--> socket
///   tick <-try_receive-- rx ring <--I/O thread-- socket (filtered to this node's commands)
/// The I/O thread waits in poll() on the socket with a 1 ms timeout, so a queued frame leaves
/// within about 1 ms (the fastest telemetry frame is every 1 ms, the heartbeat every 100 ms).
/// A frame the socket refuses (its queue full, or the controller bus-off) stays at the head of
/// the tx ring and is retried; once the ring is full the tick's try_send fails and the drive
/// counts the drop.
#include <atomic>
#include <cstdint>
#include <memory>
#include <string>
#include <thread>
#include <vector>

#include "hal/can_bus.hpp"
#include "hal/linux/socketcan_bus.hpp"
#include "hal/spsc_ring.hpp"

namespace imd::hal {

/// What the I/O thread has seen, for reports. Counters since open().
struct QueuedCanCounters {
  uint64_t sent = 0;             ///< frames written to the socket
  uint64_t received = 0;         ///< frames queued for the tick
  uint64_t rx_dropped = 0;       ///< received while the rx ring was full
  uint64_t tx_retries = 0;       ///< writes the socket refused (retried)
  uint64_t error_frames = 0;     ///< CAN error frames
  uint64_t bus_off_events = 0;   ///< bus-off error frames
  uint32_t last_error_class = 0; ///< CAN_ERR_* bits of the last error frame
};

class QueuedCanBus final : public CanBus {
 public:
  static constexpr std::size_t kRingFrames = 256;

  /// Opens `iface` (SocketCanBus::open, with `filters`) and starts the I/O thread. nullptr and
  /// `error` on failure.
  static std::unique_ptr<QueuedCanBus> open(const std::string& iface, std::string& error,
                                            const std::vector<CanIdFilter>& filters = {});
  /// Stops the I/O thread after it has sent what is queued (up to 100 ms).
  ~QueuedCanBus();
  QueuedCanBus(const QueuedCanBus&) = delete;
  QueuedCanBus& operator=(const QueuedCanBus&) = delete;

  // Tick side: lock-free, no system call.
  bool try_send(const CanFrame& frame) noexcept override { return tx_.try_push(frame); }
  bool try_receive(CanFrame& frame) noexcept override { return rx_.try_pop(frame); }
  bool bus_off() const noexcept override { return bus_off_.load(std::memory_order_relaxed); }

  /// Waits (up to `timeout_ms`) until the I/O thread has written every queued frame; false if
  /// frames remain. For a clean stop: the final heartbeat leaves before the socket closes.
  bool flush(int timeout_ms) noexcept;
  QueuedCanCounters counters() const noexcept;
  const std::string& iface() const noexcept { return socket_->iface(); }

 private:
  explicit QueuedCanBus(std::unique_ptr<SocketCanBus> socket);
  void run_io() noexcept;
  /// Moves what the socket has received into the rx ring, and the tx ring to the socket.
  void exchange() noexcept;

  std::unique_ptr<SocketCanBus> socket_;  ///< used by the I/O thread only
  SpscRing<CanFrame, kRingFrames> tx_;    ///< tick -> I/O thread
  SpscRing<CanFrame, kRingFrames> rx_;    ///< I/O thread -> tick
  std::atomic<bool> bus_off_{false};
  std::atomic<bool> stop_{false};
  std::atomic<uint64_t> sent_{0}, received_{0}, rx_dropped_{0}, tx_retries_{0};
  std::atomic<uint64_t> error_frames_{0}, bus_off_events_{0};
  std::atomic<uint32_t> last_error_class_{0};
  std::thread io_;
};

}  // namespace imd::hal
