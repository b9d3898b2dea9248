#pragma once
/// hal::CanBus served over TCP in the socketcand protocol's raw mode
/// (github.com/linux-can/socketcand, doc/protocol.md), for a machine without SocketCAN (a
/// container, WSL, CI): any socketcand client (imdrive.SocketcandBus, python-can's
/// `socketcand` interface) is then the other node on the drive's bus.
///   tick --try_send--> tx ring --I/O thread--> `< frame ID SEC.USEC DATA >` to the client
///   tick <-try_receive-- rx ring <--I/O thread-- `< send ID LEN B0 .. >` from the client
/// The same queue semantics as QueuedCanBus: the tick touches only two lock-free rings, and
/// one I/O thread waits in poll() (1 ms) on the listening socket and the client. One client
/// at a time: another is answered `< error busy >` and closed. A client that leaves leaves the
/// drive running (its command watchdog sees the silence); the next one may connect. A client
/// that is not in raw mode 3 s after connecting, or whose peer vanished (TCP keepalive, about
/// 5 s), or that leaves 64 KiB of answers unread, is dropped. Frames of the drive while no
/// client is in raw mode are dropped and counted; while the client reads too slowly
/// (kMaxPendingOutput_bytes unsent) they stay queued and are retried, and the client is not
/// read; once the ring is full the drive counts the telemetry it could not queue.
#include <atomic>
#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <thread>
#include <vector>

#include "hal/can_bus.hpp"
#include "hal/linux/queued_can_bus.hpp"
#include "hal/linux/socketcan_bus.hpp"
#include "hal/spsc_ring.hpp"

namespace imd::hal {

/// What only a socketcand server has seen. Counters since open().
struct SocketcandCounters {
  uint64_t clients = 0;            ///< clients accepted
  uint64_t clients_refused = 0;    ///< answered `< error busy >`: another was connected
  uint64_t dropped_no_client = 0;  ///< frames of the drive with no client in raw mode
  uint64_t client_errors = 0;      ///< client messages answered `< error ... >`
  uint64_t filtered = 0;           ///< frames of the client outside the filters
  uint64_t clients_dropped = 0;    ///< closed: not in raw mode in time, or answers left unread
};

/// Told, from the I/O thread, of clients coming and going and of their errors (one line each).
using SocketcandLog = std::function<void(const std::string& line)>;

class SocketcandServer final : public CanBus {
 public:
  static constexpr std::size_t kRingFrames = QueuedCanBus::kRingFrames;
  /// Unsent text for the client beyond which frames wait in the ring: about 100 ms of the
  /// fastest telemetry (1 kHz, ~40 bytes a frame) and the heartbeats.
  /// The client is not read either while this much is unsent, so that a client that sends
  /// without reading cannot grow its answers without limit.
  static constexpr std::size_t kMaxPendingOutput_bytes = 8192;
  /// Unsent text beyond which the client is dropped (logged, counted in clients_dropped): the
  /// gate above allows only the answers to one read past it, so this is a backstop that keeps
  /// the drive's locked memory bounded.
  static constexpr std::size_t kMaxClientOutput_bytes = 64 * 1024;

  /// Listens on `host` (a numeric IPv4 or IPv6 address, or localhost: no name lookup, as the
  /// program may be linked statically) and `port` (0: any free port,
  /// address() tells which) and starts the I/O thread. Frames from the client pass when they
  /// match one of `filters` (none: all). nullptr and `error` on failure, e.g. "socketcand
  /// 127.0.0.1:29536: bind: Address already in use".
  static std::unique_ptr<SocketcandServer> open(const std::string& host, uint16_t port,
                                                std::string& error,
                                                const std::vector<CanIdFilter>& filters = {},
                                                SocketcandLog log = {});
  /// Stops the I/O thread after it has sent what is queued (up to 100 ms), closes the sockets.
  ~SocketcandServer();
  SocketcandServer(const SocketcandServer&) = delete;
  SocketcandServer& operator=(const SocketcandServer&) = delete;

  // Tick side: lock-free, no system call.
  bool try_send(const CanFrame& frame) noexcept override { return tx_.try_push(frame); }
  bool try_receive(CanFrame& frame) noexcept override { return rx_.try_pop(frame); }

  /// Waits (up to `timeout_ms`) until every queued frame has been written to the client (or
  /// dropped, with none); false if some remain.
  bool flush(int timeout_ms) noexcept;
  /// sent: frames written to the client; received, rx_dropped: frames from the client queued
  /// for the tick, or dropped with the rx ring full; tx_retries: frames held back by a client
  /// reading too slowly (each counted once, however long it waits). No error frames over TCP.
  QueuedCanCounters counters() const noexcept;
  SocketcandCounters socketcand_counters() const noexcept;
  /// "127.0.0.1:29536", "[::1]:29536": where it listens, with the port bound.
  const std::string& address() const noexcept { return address_; }
  /// Unsent text for the client, bytes (at most about kMaxPendingOutput_bytes plus the answers
  /// to one read).
  std::size_t pending_output_bytes() const noexcept { return pending_output_bytes_.load(); }
  /// Whether a client is connected (in any mode).
  bool client_connected() const noexcept { return client_connected_.load(); }

 private:
  struct Client;
  SocketcandServer(int listen_fd, std::string address, std::vector<CanIdFilter> filters,
                   SocketcandLog log);
  void run_io() noexcept;
  void accept_clients() noexcept;
  void read_client() noexcept;
  void write_client() noexcept;
  void drop_client() noexcept;
  /// The tx ring to the client's output (or dropped without one in raw mode).
  void drain_tx() noexcept;

  int listen_fd_;
  std::string address_;
  std::vector<CanIdFilter> filters_;
  SocketcandLog log_;
  std::unique_ptr<Client> client_;  ///< I/O thread only; null while none is connected
  bool front_held_ = false;         ///< I/O thread only: the tx ring's oldest frame is counted held
  SpscRing<CanFrame, kRingFrames> tx_;  ///< tick -> I/O thread
  SpscRing<CanFrame, kRingFrames> rx_;  ///< I/O thread -> tick
  std::atomic<bool> stop_{false};
  std::atomic<bool> client_connected_{false};
  std::atomic<std::size_t> pending_output_bytes_{0};
  std::atomic<uint64_t> sent_{0}, received_{0}, rx_dropped_{0}, tx_retries_{0};
  std::atomic<uint64_t> clients_{0}, clients_refused_{0}, dropped_no_client_{0};
  std::atomic<uint64_t> client_errors_{0}, filtered_{0}, clients_dropped_{0};
  std::thread io_;
};

}  // namespace imd::hal
