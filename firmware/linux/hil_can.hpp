#pragma once
/// drive_hil's CAN link, chosen by --can: a SocketCAN interface (hal::QueuedCanBus), or, on a
/// machine without SocketCAN (a container, WSL, CI), a socketcand server on TCP
/// (hal::SocketcandServer, `--can socketcand:[HOST:]PORT`). Either way the drive sees one
/// hal::CanBus with the same queue semantics, and only its node's 32 identifiers come in.
#include <cstdint>
#include <memory>
#include <optional>
#include <string>

#include "firmware/linux/hil_report.hpp"
#include "hal/can_bus.hpp"
#include "hal/linux/queued_can_bus.hpp"
#include "hal/linux/socketcand_server.hpp"

namespace imd::firmware {

/// What --can names.
struct HilCanSpec {
  bool socketcand = false;
  std::string iface;               ///< SocketCAN: the interface
  std::string host = "127.0.0.1";  ///< socketcand: where to listen (loopback unless told)
  uint16_t port = 0;               ///< socketcand: the TCP port (0: any free one)
};

/// The prefix of the socketcand form of --can.
inline constexpr const char* kSocketcandPrefix = "socketcand:";

/// Parses --can's text: "vcan0"; "socketcand:29536", "socketcand:0.0.0.0:29536",
/// "socketcand:[::1]:29536". nullopt and `error` (naming the text) if it is malformed.
std::optional<HilCanSpec> parse_hil_can(const std::string& text, std::string& error);

class HilCan {
 public:
  /// Opens the link for node `node`. SocketCAN: the interface must run at `bit_rate_bit_s`
  /// (a virtual one has none). socketcand: `log` is told of clients coming and going. nullptr
  /// and `error` on failure.
  static std::unique_ptr<HilCan> open(const HilCanSpec& spec, int node, uint32_t bit_rate_bit_s,
                                      std::string& error, hal::SocketcandLog log = {});

  hal::CanBus* bus() noexcept;
  /// Waits until the queued frames have left (up to `timeout_ms`); false if some remain.
  bool flush(int timeout_ms) noexcept;
  /// For the report's `can.iface`: "vcan0", "socketcand:127.0.0.1:29536".
  std::string name() const;
  /// Adds the link's counters to the report.
  void report(HilRunFacts& facts) const;
  /// Set for socketcand: where it listens, with the port bound ("127.0.0.1:29536").
  std::string socketcand_address() const;

 private:
  std::unique_ptr<hal::QueuedCanBus> socketcan_;
  std::unique_ptr<hal::SocketcandServer> socketcand_;
};

}  // namespace imd::firmware
