#include "pmu/transport/socket_ops.hpp"

#include <linux/can.h>
#include <net/if.h>
#include <sys/ioctl.h>

#include <cerrno>
#include <cstring>

namespace pmu::transport {
namespace {

// -errno of the call that just failed, for the SocketOps convention.
int failed() noexcept { return -errno; }

class SystemSocketOps final : public SocketOps {
 public:
  int open_can_raw() override {
    const int fd = ::socket(PF_CAN, SOCK_RAW | SOCK_NONBLOCK | SOCK_CLOEXEC, CAN_RAW);
    return fd >= 0 ? fd : failed();
  }

  int set_option(int fd, int level, int name, const void* value, socklen_t size) override {
    return ::setsockopt(fd, level, name, value, size) == 0 ? 0 : failed();
  }

  int get_option(int fd, int level, int name, void* value, socklen_t* size) override {
    return ::getsockopt(fd, level, name, value, size) == 0 ? 0 : failed();
  }

  int interface_index(const std::string& name) override {
    const unsigned int index = ::if_nametoindex(name.c_str());
    if (index == 0) return errno == 0 ? -ENODEV : failed();
    return static_cast<int>(index);
  }

  int interface_up(int fd, const std::string& name) override {
    struct ifreq request {};
    if (name.size() >= sizeof(request.ifr_name)) return -ENAMETOOLONG;
    std::memcpy(request.ifr_name, name.data(), name.size());
    if (::ioctl(fd, SIOCGIFFLAGS, &request) != 0) return failed();
    return (request.ifr_flags & IFF_UP) != 0 ? 1 : 0;
  }

  int bind_can(int fd, int ifindex) override {
    struct sockaddr_can address {};
    address.can_family = AF_CAN;
    address.can_ifindex = ifindex;
    // sockaddr_can is one of the sockaddr family types bind() is declared to take; the
    // cast is the API's, not a reinterpretation of our data.
    return ::bind(fd, reinterpret_cast<const struct sockaddr*>(&address), sizeof(address)) == 0 ? 0 : failed();
  }

  int receive(int fd, struct mmsghdr* messages, unsigned int count) override {
    const int received = ::recvmmsg(fd, messages, count, MSG_DONTWAIT, nullptr);
    return received >= 0 ? received : failed();
  }

  ssize_t send(int fd, const void* data, size_t size) override {
    const ssize_t sent = ::send(fd, data, size, MSG_DONTWAIT | MSG_NOSIGNAL);
    return sent >= 0 ? sent : failed();
  }

  int poll(struct pollfd* fds, nfds_t count, int timeout_ms) override {
    const int ready = ::poll(fds, count, timeout_ms);
    return ready >= 0 ? ready : failed();
  }
};

}  // namespace

SocketOps& system_socket_ops() noexcept {
  static SystemSocketOps ops;
  return ops;
}

}  // namespace pmu::transport
