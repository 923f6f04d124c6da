#include "link/udp_endpoint.hpp"

#include <netdb.h>
#include <sys/socket.h>
#include <sys/types.h>

#include <array>
#include <cerrno>
#include <cstring>
#include <memory>

namespace pmu::mavlink_bridge {

UdpEndpoint::UdpEndpoint(const UdpAddress& address)
    : description_("udp " + address.host + ":" + std::to_string(address.port)) {
  addrinfo hints{};
  hints.ai_family = AF_UNSPEC;
  hints.ai_socktype = SOCK_DGRAM;
  addrinfo* found = nullptr;
  const int rc = ::getaddrinfo(address.host.c_str(), std::to_string(address.port).c_str(), &hints, &found);
  if (rc != 0) throw LinkError("cannot resolve " + description_ + ": " + ::gai_strerror(rc));
  std::unique_ptr<addrinfo, void (*)(addrinfo*)> list(found, ::freeaddrinfo);
  std::string last_error = "no address";
  for (const addrinfo* a = list.get(); a; a = a->ai_next) {
    pmu::transport::UniqueFd s(::socket(a->ai_family, a->ai_socktype | SOCK_NONBLOCK | SOCK_CLOEXEC, a->ai_protocol));
    if (!s) {
      last_error = std::strerror(errno);
      continue;
    }
    if (::connect(s.get(), a->ai_addr, a->ai_addrlen) != 0) {
      last_error = std::strerror(errno);
      continue;
    }
    fd_ = std::move(s);
    return;
  }
  throw LinkError("cannot open " + description_ + ": " + last_error);
}

bool UdpEndpoint::read_available(std::vector<std::uint8_t>& out) {
  std::array<std::uint8_t, 65536> buffer{};
  for (;;) {
    const ssize_t n = ::recv(fd_.get(), buffer.data(), buffer.size(), 0);
    if (n >= 0) {
      out.insert(out.end(), buffer.begin(), buffer.begin() + n);
      counters_.bytes_in += static_cast<std::uint64_t>(n);
      continue;
    }
    if (errno == EINTR) continue;
    if (errno == EAGAIN || errno == EWOULDBLOCK) return true;
    // ECONNREFUSED: an earlier datagram met no listener (ICMP). The ground station may
    // start later, so it is counted and the link stays.
    ++counters_.read_failures;
    return true;
  }
}

void UdpEndpoint::send(const std::vector<std::uint8_t>& frame) {
  const ssize_t n = ::send(fd_.get(), frame.data(), frame.size(), MSG_NOSIGNAL);
  if (n == static_cast<ssize_t>(frame.size())) {
    counters_.bytes_out += frame.size();
    ++counters_.frames_out;
  } else {
    ++counters_.send_failures;
  }
}

}  // namespace pmu::mavlink_bridge
