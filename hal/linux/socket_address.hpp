#pragma once
/// The socketcand server's and client's TCP addresses: a numeric IPv4 or IPv6 address, or
/// "localhost". No name lookup: drive_hil and drive_monitor are also linked statically, where
/// glibc's resolver needs the shared libraries static linking was meant to avoid.
#include <sys/socket.h>

#include <cstdint>
#include <string>

namespace imd::hal {

/// Fills `address` and `length` for `host` and `port`; false if `host` is not numeric.
bool numeric_address(const std::string& host, uint16_t port, sockaddr_storage& address,
                     socklen_t& length);

}  // namespace imd::hal
