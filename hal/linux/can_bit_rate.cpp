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

/// The attribute's type without the nested / byte-order flags some kernels set.
int type_of(const rtattr* a) {
  return a->rta_type & NLA_TYPE_MASK;
}

/// IFLA_INFO_KIND and, inside IFLA_INFO_DATA, IFLA_CAN_BITTIMING of an IFLA_LINKINFO attribute.
void read_link_info(const rtattr* link_info, CanLinkInfo& info) {
  int length = static_cast<int>(RTA_PAYLOAD(link_info));
  for (auto* a = static_cast<const rtattr*>(RTA_DATA(link_info)); RTA_OK(a, length);
       a = RTA_NEXT(a, length)) {
    if (type_of(a) == IFLA_INFO_KIND) {
      info.kind.assign(static_cast<const char*>(RTA_DATA(a)), strnlen(static_cast<const char*>(
                                                                  RTA_DATA(a)), RTA_PAYLOAD(a)));
    } else if (type_of(a) == IFLA_INFO_DATA) {
      int data_length = static_cast<int>(RTA_PAYLOAD(a));
      for (auto* d = static_cast<const rtattr*>(RTA_DATA(a)); RTA_OK(d, data_length);
           d = RTA_NEXT(d, data_length)) {
        if (type_of(d) == IFLA_CAN_BITTIMING && RTA_PAYLOAD(d) >= sizeof(can_bittiming)) {
          can_bittiming timing{};
          std::memcpy(&timing, RTA_DATA(d), sizeof timing);
          info.bit_rate_bit_s = timing.bitrate;
        }
      }
    }
  }
}

}  // namespace

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
  std::vector<char> answer(32 * 1024);  // one link's attributes, statistics included
  ssize_t received = -1;
  if (send(fd, &request, request.header.nlmsg_len, 0) >= 0) {
    received = recv(fd, answer.data(), answer.size(), 0);
  }
  const int recv_errno = errno;
  close(fd);
  auto* header = reinterpret_cast<const nlmsghdr*>(answer.data());
  if (received < 0 || !NLMSG_OK(header, static_cast<unsigned>(received)) ||
      header->nlmsg_type != RTM_NEWLINK) {
    error = iface + ": rtnetlink gave no link information (" +
            (received < 0 ? std::strerror(recv_errno) : "unexpected answer") + ")";
    return std::nullopt;
  }
  CanLinkInfo info{"", 0};
  const auto* link = static_cast<const ifinfomsg*>(NLMSG_DATA(header));
  int length = static_cast<int>(IFLA_PAYLOAD(header));
  for (const rtattr* a = IFLA_RTA(link); RTA_OK(a, length); a = RTA_NEXT(a, length)) {
    if (type_of(a) == IFLA_LINKINFO) read_link_info(a, info);
  }
  return info;
}

std::string bit_rate_mismatch(const std::string& iface, uint32_t bit_rate_bit_s) {
  std::string error;
  const std::optional<CanLinkInfo> info = can_link_info(iface, error);
  if (!info) return error;
  if (info->kind == "vcan" || info->kind == "vxcan") return {};  // virtual: no bit rate
  const std::string fix = "ip link set " + iface + " down; ip link set " + iface +
                          " type can bitrate " + std::to_string(bit_rate_bit_s) + "; ip link set " +
                          iface + " up";
  if (info->kind != "can") {
    return iface + ": not a CAN interface (link kind '" + info->kind + "')";
  }
  if (info->bit_rate_bit_s == 0) {
    return iface + ": no bit rate configured, the protocol runs at " +
           std::to_string(bit_rate_bit_s) + " bit/s: " + fix;
  }
  if (info->bit_rate_bit_s != bit_rate_bit_s) {
    return iface + ": runs at " + std::to_string(info->bit_rate_bit_s) +
           " bit/s, the protocol at " + std::to_string(bit_rate_bit_s) + " bit/s: " + fix;
  }
  return {};
}

}  // namespace imd::hal
