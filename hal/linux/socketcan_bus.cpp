#include "hal/linux/socketcan_bus.hpp"

#include <linux/can/error.h>
#include <linux/can/raw.h>
#include <net/if.h>
#include <sys/ioctl.h>
#include <sys/socket.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>

namespace imd::hal {
namespace {

constexpr int kMaxReadsPerReceive = 64;  // bounds try_receive under a flood of error frames

std::string errno_text(int error) {
  return std::strerror(error);
}

/// Closes the socket on every early return of open().
struct SocketGuard {
  int fd;
  ~SocketGuard() {
    if (fd >= 0) ::close(fd);
  }
  int release() noexcept {
    const int owned = fd;
    fd = -1;
    return owned;
  }
};

}  // namespace

bool from_socketcan(const can_frame& in, CanFrame& out) noexcept {
  if ((in.can_id & (CAN_EFF_FLAG | CAN_RTR_FLAG | CAN_ERR_FLAG)) != 0) return false;
  if (in.len > CAN_MAX_DLEN) return false;
  out.id = static_cast<uint16_t>(in.can_id & CAN_SFF_MASK);
  out.length = in.len;
  out.data = {};
  for (int i = 0; i < in.len; ++i) out.data[i] = in.data[i];
  return true;
}

bool to_socketcan(const CanFrame& in, can_frame& out) noexcept {
  if (in.id > CAN_SFF_MASK || in.length > CAN_MAX_DLEN) return false;
  std::memset(&out, 0, sizeof out);
  out.can_id = in.id;
  out.len = in.length;
  for (int i = 0; i < in.length; ++i) out.data[i] = in.data[i];
  return true;
}

void account_error_frame(const can_frame& frame, CanErrorState& state) noexcept {
  if ((frame.can_id & CAN_ERR_FLAG) == 0) return;
  const uint32_t error_class = frame.can_id & CAN_ERR_MASK;
  ++state.error_frames;
  state.last_error_class = error_class;
  if ((error_class & CAN_ERR_BUSOFF) != 0) {
    ++state.bus_off_events;
    state.bus_off = true;
  } else if ((error_class & CAN_ERR_RESTARTED) != 0) {
    state.bus_off = false;
  }
}

std::string describe_error_class(uint32_t error_class) {
  static constexpr struct {
    uint32_t bit;
    const char* name;
  } kNames[] = {
      {CAN_ERR_TX_TIMEOUT, "tx-timeout"}, {CAN_ERR_LOSTARB, "lost-arbitration"},
      {CAN_ERR_CRTL, "controller"},       {CAN_ERR_PROT, "protocol-violation"},
      {CAN_ERR_TRX, "transceiver"},       {CAN_ERR_ACK, "no-ack"},
      {CAN_ERR_BUSOFF, "bus-off"},        {CAN_ERR_BUSERROR, "bus-error"},
      {CAN_ERR_RESTARTED, "restarted"},   {CAN_ERR_CNT, "error-counters"},
  };
  std::string text;
  for (const auto& entry : kNames) {
    if ((error_class & entry.bit) == 0) continue;
    if (!text.empty()) text += ", ";
    text += entry.name;
  }
  return text.empty() ? "none" : text;
}

std::unique_ptr<SocketCanBus> SocketCanBus::open(const std::string& iface, std::string& error,
                                                 const std::vector<CanIdFilter>& filters) {
  if (iface.empty()) {
    error = "empty CAN interface name";
    return nullptr;
  }
  if (iface.size() >= IFNAMSIZ) {
    error = iface + ": interface name longer than " + std::to_string(IFNAMSIZ - 1) + " characters";
    return nullptr;
  }
  SocketGuard socket_fd{::socket(PF_CAN, SOCK_RAW | SOCK_NONBLOCK | SOCK_CLOEXEC, CAN_RAW)};
  if (socket_fd.fd < 0) {
    const int e = errno;
    error = iface + ": socket(PF_CAN): " + errno_text(e);
    if (e == EAFNOSUPPORT) error += " (no CAN support in this kernel)";
    if (e == EPROTONOSUPPORT) error += " (no CAN_RAW support in this kernel: modprobe can_raw)";
    return nullptr;
  }
  const unsigned index = ::if_nametoindex(iface.c_str());
  if (index == 0) {
    const int e = errno;
    error = e == ENODEV ? iface + ": no such CAN interface"
                        : iface + ": if_nametoindex: " + errno_text(e);
    return nullptr;
  }
  const can_err_mask_t error_mask = CAN_ERR_MASK;
  if (::setsockopt(socket_fd.fd, SOL_CAN_RAW, CAN_RAW_ERR_FILTER, &error_mask, sizeof error_mask) !=
      0) {
    error = iface + ": setsockopt(CAN_RAW_ERR_FILTER): " + errno_text(errno);
    return nullptr;
  }
  if (!filters.empty()) {
    // The flag bits in the mask keep extended and remote frames with matching low bits out.
    std::vector<can_filter> kernel_filters;
    for (const CanIdFilter& f : filters) {
      kernel_filters.push_back(
          {f.id & CAN_SFF_MASK, (f.mask & CAN_SFF_MASK) | CAN_EFF_FLAG | CAN_RTR_FLAG});
    }
    if (::setsockopt(socket_fd.fd, SOL_CAN_RAW, CAN_RAW_FILTER, kernel_filters.data(),
                     socklen_t(kernel_filters.size() * sizeof(can_filter))) != 0) {
      error = iface + ": setsockopt(CAN_RAW_FILTER): " + errno_text(errno);
      return nullptr;
    }
  }
  sockaddr_can address{};
  address.can_family = AF_CAN;
  address.can_ifindex = static_cast<int>(index);
  if (::bind(socket_fd.fd, reinterpret_cast<const sockaddr*>(&address), sizeof address) != 0) {
    const int e = errno;
    error = e == ENODEV ? iface + ": not a CAN interface" : iface + ": bind: " + errno_text(e);
    return nullptr;
  }
  ifreq request{};
  std::memcpy(request.ifr_name, iface.c_str(), iface.size() + 1);
  if (::ioctl(socket_fd.fd, SIOCGIFFLAGS, &request) == 0 && (request.ifr_flags & IFF_UP) == 0) {
    error = iface + ": interface is down (ip link set " + iface + " up)";
    return nullptr;
  }
  return std::unique_ptr<SocketCanBus>(new SocketCanBus(socket_fd.release(), iface));
}

SocketCanBus::~SocketCanBus() {
  if (fd_ >= 0) ::close(fd_);
}

bool SocketCanBus::try_send(const CanFrame& frame) noexcept {
  can_frame out;
  if (!to_socketcan(frame, out)) {
    ++send_failures_;
    return false;
  }
  const ssize_t written = ::write(fd_, &out, sizeof out);
  if (written == static_cast<ssize_t>(sizeof out)) return true;
  ++send_failures_;
  // A full queue (EAGAIN, or ENOBUFS from the driver's queue) is the expected failure.
  if (written < 0 && errno != EAGAIN && errno != EWOULDBLOCK && errno != ENOBUFS) {
    last_errno_ = errno;
  }
  return false;
}

bool SocketCanBus::try_receive(CanFrame& frame) noexcept {
  for (int i = 0; i < kMaxReadsPerReceive; ++i) {
    can_frame in;
    const ssize_t received = ::read(fd_, &in, sizeof in);
    if (received < 0) {
      if (errno == EINTR) continue;
      if (errno != EAGAIN && errno != EWOULDBLOCK) last_errno_ = errno;
      return false;
    }
    if (received != static_cast<ssize_t>(sizeof in)) {
      ++unsupported_frames_;
      continue;
    }
    if ((in.can_id & CAN_ERR_FLAG) != 0) {
      account_error_frame(in, errors_);
      continue;
    }
    if (from_socketcan(in, frame)) return true;
    ++unsupported_frames_;
  }
  return false;
}

}  // namespace imd::hal
