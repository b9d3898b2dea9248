#include "firmware/linux/hil_can.hpp"

#include <charconv>
#include <utility>

#include "hal/linux/can_bit_rate.hpp"

namespace imd::firmware {
namespace {

/// This node's message ids only: the block of 32 ids at node * 32.
hal::CanIdFilter node_ids(int node) {
  return {static_cast<uint16_t>(node * 32), 0x7E0};
}

}  // namespace

std::optional<HilCanSpec> parse_hil_can(const std::string& text, std::string& error) {
  HilCanSpec spec;
  const std::string prefix = kSocketcandPrefix;
  if (text == "socketcand") {
    error = "--can socketcand: give the TCP port to listen on, e.g. socketcand:29536";
    return std::nullopt;
  }
  if (text.rfind(prefix, 0) != 0) {
    spec.iface = text;
    return spec;
  }
  spec.socketcand = true;
  const std::string rest = text.substr(prefix.size());
  const std::size_t colon = rest.rfind(':');
  const std::string port = colon == std::string::npos ? rest : rest.substr(colon + 1);
  if (colon != std::string::npos) {
    std::string host = rest.substr(0, colon);
    if (host.size() >= 2 && host.front() == '[' && host.back() == ']') {
      host = host.substr(1, host.size() - 2);  // [::1]
    }
    if (host.empty()) {
      error = "--can " + text + ": empty host before the port, e.g. socketcand:127.0.0.1:29536";
      return std::nullopt;
    }
    spec.host = host;
  }
  unsigned value = 0;
  const auto [end, status] = std::from_chars(port.data(), port.data() + port.size(), value);
  if (port.empty() || status != std::errc{} || end != port.data() + port.size() || value > 65535) {
    error = "--can " + text + ": '" + port +
            "' is not a TCP port (0..65535), e.g. socketcand:29536 or socketcand:0.0.0.0:29536";
    return std::nullopt;
  }
  spec.port = static_cast<uint16_t>(value);
  return spec;
}

std::unique_ptr<HilCan> HilCan::open(const HilCanSpec& spec, int node, uint32_t bit_rate_bit_s,
                                     std::string& error, hal::SocketcandLog log) {
  std::unique_ptr<HilCan> can(new HilCan());
  if (spec.socketcand) {
    can->socketcand_ =
        hal::SocketcandServer::open(spec.host, spec.port, error, {node_ids(node)}, std::move(log));
    return can->socketcand_ ? std::move(can) : nullptr;
  }
  can->socketcan_ = hal::QueuedCanBus::open(spec.iface, error, {node_ids(node)});
  if (!can->socketcan_) {
    if (error.find("no CAN support") != std::string::npos) {
      error += "; without SocketCAN, serve the bus over TCP instead: --can socketcand:29536";
    }
    return nullptr;
  }
  // A CAN controller at another bit rate would disturb the whole bus: refused before the
  // drive sends anything.
  error = hal::bit_rate_mismatch(spec.iface, bit_rate_bit_s);
  return error.empty() ? std::move(can) : nullptr;
}

hal::CanBus* HilCan::bus() noexcept {
  if (socketcand_) return socketcand_.get();
  return socketcan_.get();
}

bool HilCan::flush(int timeout_ms) noexcept {
  return socketcand_ ? socketcand_->flush(timeout_ms) : socketcan_->flush(timeout_ms);
}

std::string HilCan::name() const {
  return socketcand_ ? kSocketcandPrefix + socketcand_->address() : socketcan_->iface();
}

std::string HilCan::socketcand_address() const {
  return socketcand_ ? socketcand_->address() : std::string();
}

void HilCan::report(HilRunFacts& facts) const {
  facts.can_iface = name();
  if (socketcand_) {
    facts.can = socketcand_->counters();
    facts.socketcand = socketcand_->socketcand_counters();
  } else {
    facts.can = socketcan_->counters();
  }
}

}  // namespace imd::firmware
