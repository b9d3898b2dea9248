#include "hal/linux/can_bit_rate.hpp"

#include <linux/can/netlink.h>
#include <linux/if_link.h>
#include <linux/netlink.h>
#include <linux/rtnetlink.h>
#include <net/if.h>
#include <sys/socket.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <vector>

namespace imd::hal {
namespace {

/// A struct copied out of `bytes` at `offset` (the answer need not be aligned for it).
template <typename T>
T read_at(std::span<const std::byte> bytes, std::size_t offset) {
  T value{};
  std::memcpy(&value, bytes.data() + offset, sizeof value);
  return value;
}

/// Calls `visit(type, payload)` for each attribute of `bytes`, the type without the nested /
/// byte-order flags some kernels set. False, with `error` set, when one is cut short.
template <typename Visit>
bool for_each_attribute(std::span<const std::byte> bytes, const char* where, std::string& error,
                        Visit&& visit) {
  std::size_t offset = 0;
  while (offset < bytes.size()) {
    const std::size_t left = bytes.size() - offset;
    const auto a = left >= sizeof(rtattr) ? read_at<rtattr>(bytes, offset) : rtattr{};
    if (left < sizeof(rtattr) || a.rta_len < sizeof(rtattr) || a.rta_len > left) {
      error = std::string("truncated answer: an attribute of ") + where + " at byte " +
              std::to_string(offset) + " claims " + std::to_string(a.rta_len) + " bytes, " +
              std::to_string(left) + " left";
      return false;
    }
    const std::size_t header = RTA_LENGTH(0);
    if (!visit(a.rta_type & NLA_TYPE_MASK, bytes.subspan(offset + header, a.rta_len - header))) {
      return false;
    }
    offset += RTA_ALIGN(a.rta_len);  // the last one's padding may be missing
  }
  return true;
}

/// IFLA_INFO_KIND and, inside IFLA_INFO_DATA, IFLA_CAN_BITTIMING of an IFLA_LINKINFO payload.
bool read_link_info(std::span<const std::byte> link_info, CanLinkInfo& info, std::string& error) {
  return for_each_attribute(link_info, "IFLA_LINKINFO", error, [&](int type, auto payload) {
    if (type == IFLA_INFO_KIND) {
      const auto* text = reinterpret_cast<const char*>(payload.data());
      info.kind.assign(text, strnlen(text, payload.size()));
    } else if (type == IFLA_INFO_DATA) {
      return for_each_attribute(payload, "IFLA_INFO_DATA", error, [&](int data_type, auto data) {
        if (data_type != IFLA_CAN_BITTIMING) return true;
        if (data.size() < sizeof(can_bittiming)) {
          error = "truncated answer: IFLA_CAN_BITTIMING of " + std::to_string(data.size()) +
                  " bytes, expected " + std::to_string(sizeof(can_bittiming));
          return false;
        }
        info.bit_rate_bit_s = read_at<can_bittiming>(data, 0).bitrate;
        return true;
      });
    }
    return true;
  });
}

constexpr std::size_t kMessageHeader_bytes = NLMSG_ALIGN(sizeof(nlmsghdr));

}  // namespace

std::optional<CanLinkInfo> parse_link_message(std::span<const std::byte> answer,
                                              std::string& error) {
  if (answer.size() < sizeof(nlmsghdr)) {
    error = "truncated answer: " + std::to_string(answer.size()) + " bytes, no message header";
    return std::nullopt;
  }
  const auto header = read_at<nlmsghdr>(answer, 0);
  if (header.nlmsg_len < kMessageHeader_bytes || header.nlmsg_len > answer.size()) {
    error = "truncated answer: " + std::to_string(answer.size()) + " bytes, the message claims " +
            std::to_string(header.nlmsg_len);
    return std::nullopt;
  }
  const std::span<const std::byte> body =
      answer.subspan(kMessageHeader_bytes, header.nlmsg_len - kMessageHeader_bytes);
  if (header.nlmsg_type == NLMSG_ERROR) {
    if (body.size() < sizeof(int)) {
      error = "truncated answer: an NLMSG_ERROR without its error code";
      return std::nullopt;
    }
    const int code = read_at<int>(body, 0);  // nlmsgerr::error: minus the errno, 0 for an ACK
    error = code == 0 ? std::string("unexpected answer: an acknowledgement, no link")
                      : std::string("the kernel answered: ") + std::strerror(-code) + " (errno " +
                            std::to_string(-code) + ")";
    return std::nullopt;
  }
  if (header.nlmsg_type != RTM_NEWLINK) {
    error = "unexpected answer: message type " + std::to_string(header.nlmsg_type) +
            ", expected RTM_NEWLINK (" + std::to_string(RTM_NEWLINK) + ")";
    return std::nullopt;
  }
  const std::size_t attributes = NLMSG_ALIGN(sizeof(ifinfomsg));
  if (body.size() < attributes) {
    error = "truncated answer: RTM_NEWLINK of " + std::to_string(body.size()) +
            " bytes, shorter than its ifinfomsg";
    return std::nullopt;
  }
  CanLinkInfo info{"", 0};
  const bool ok = for_each_attribute(
      body.subspan(attributes), "RTM_NEWLINK", error,
      [&](int type, auto a) { return type != IFLA_LINKINFO || read_link_info(a, info, error); });
  if (!ok) return std::nullopt;
  return info;
}

std::optional<CanLinkInfo> can_link_info(const std::string& iface, std::string& error) {
  const unsigned index = if_nametoindex(iface.c_str());
  if (index == 0) {
    error = iface + ": no such network interface";
    return std::nullopt;
  }
  const int fd = socket(AF_NETLINK, SOCK_RAW | SOCK_CLOEXEC, NETLINK_ROUTE);
  if (fd < 0) {
    error = iface + ": cannot open an rtnetlink socket (" + std::strerror(errno) + ")";
    return std::nullopt;
  }
  struct {
    nlmsghdr header;
    ifinfomsg link;
  } request{};
  request.header.nlmsg_len = NLMSG_LENGTH(sizeof(ifinfomsg));
  request.header.nlmsg_type = RTM_GETLINK;
  request.header.nlmsg_flags = NLM_F_REQUEST;
  request.link.ifi_family = AF_UNSPEC;
  request.link.ifi_index = static_cast<int>(index);
  std::vector<std::byte> answer(32 * 1024);  // one link's attributes, statistics included
  ssize_t received = -1;
  if (send(fd, &request, request.header.nlmsg_len, 0) >= 0) {
    received = recv(fd, answer.data(), answer.size(), 0);
  }
  const int recv_errno = errno;
  close(fd);
  if (received < 0) {
    error = iface + ": rtnetlink gave no link information (" + std::strerror(recv_errno) + ")";
    return std::nullopt;
  }
  std::string why;
  std::optional<CanLinkInfo> info =
      parse_link_message(std::span(answer).first(static_cast<std::size_t>(received)), why);
  if (!info) error = iface + ": rtnetlink gave no link information (" + why + ")";
  return info;
}

std::string bit_rate_mismatch(const std::string& iface, uint32_t bit_rate_bit_s) {
  std::string error;
  const std::optional<CanLinkInfo> info = can_link_info(iface, error);
  return info ? bit_rate_mismatch(iface, *info, bit_rate_bit_s) : error;
}

std::string bit_rate_mismatch(const std::string& iface, const CanLinkInfo& info,
                              uint32_t bit_rate_bit_s) {
  if (info.kind == "vcan" || info.kind == "vxcan") return {};  // virtual: no bit rate
  const std::string fix = "ip link set " + iface + " down; ip link set " + iface +
                          " type can bitrate " + std::to_string(bit_rate_bit_s) + "; ip link set " +
                          iface + " up";
  if (info.kind != "can") {
    return iface + ": not a CAN interface (link kind '" + info.kind + "')";
  }
  if (info.bit_rate_bit_s == 0) {
    return iface + ": no bit rate configured, the protocol runs at " +
           std::to_string(bit_rate_bit_s) + " bit/s: " + fix;
  }
  if (info.bit_rate_bit_s != bit_rate_bit_s) {
    return iface + ": runs at " + std::to_string(info.bit_rate_bit_s) + " bit/s, the protocol at " +
           std::to_string(bit_rate_bit_s) + " bit/s: " + fix;
  }
  return {};
}

}  // namespace imd::hal
