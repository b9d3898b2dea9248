#pragma once
/// The bit rate a SocketCAN interface is configured for, read over rtnetlink (RTM_GETLINK: the
/// link's kind and, for a CAN controller, IFLA_CAN_BITTIMING), so that a program can refuse a
/// bus that runs at another rate than its protocol's before it sends anything. Start-up only.
#include <cstddef>
#include <cstdint>
#include <optional>
#include <span>
#include <string>

namespace imd::hal {

struct CanLinkInfo {
  std::string kind;         ///< IFLA_INFO_KIND: "can", "vcan", "vxcan", ... ("" for none)
  uint32_t bit_rate_bit_s;  ///< a CAN controller's nominal bit rate; 0: none configured
};

/// The link info of `iface`, or nullopt with `error` saying why (no such interface, no answer,
/// the kernel's error with its errno).
std::optional<CanLinkInfo> can_link_info(const std::string& iface, std::string& error);

/// The link info in one rtnetlink answer to RTM_GETLINK (the bytes recv() gave), or nullopt
/// with `error` saying what the answer was instead: an NLMSG_ERROR with its errno, another
/// message type, or a message or attribute cut short. Pure: no socket, any alignment.
std::optional<CanLinkInfo> parse_link_message(std::span<const std::byte> answer,
                                              std::string& error);

/// Empty when `iface` may carry a protocol at `bit_rate_bit_s`: a CAN controller configured for
/// it, or a virtual CAN interface (which has no bit rate). Otherwise why not, naming the
/// interface, both rates and the command that sets the right one.
std::string bit_rate_mismatch(const std::string& iface, uint32_t bit_rate_bit_s);
/// The same for link info already read (`iface` only names it in the text).
std::string bit_rate_mismatch(const std::string& iface, const CanLinkInfo& info,
                              uint32_t bit_rate_bit_s);

}  // namespace imd::hal
