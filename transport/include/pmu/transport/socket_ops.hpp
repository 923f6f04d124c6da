#pragma once
// The system calls SocketCanBus makes on its socket, behind an interface so tests can make
// them fail the way a real CAN interface does (ENETDOWN when the link goes down, ENODEV when
// the interface is removed, ENOBUFS when the transmit queue is full) and can stand a
// socketpair in for an AF_CAN socket. This kernel has no CAN support, so those paths could
// not be tested any other way here.
//
// Convention: every call returns what the syscall returns on success and -errno on failure
// (never -1 with errno set), so a fake needs no errno plumbing and callers read one value.

#include <poll.h>
#include <sys/socket.h>
#include <sys/types.h>

#include <string>

namespace pmu::transport {

class SocketOps {
 public:
  virtual ~SocketOps() = default;

  // socket(PF_CAN, SOCK_RAW | SOCK_NONBLOCK | SOCK_CLOEXEC, CAN_RAW): a new fd.
  virtual int open_can_raw() = 0;
  virtual int set_option(int fd, int level, int name, const void* value, socklen_t size) = 0;
  virtual int get_option(int fd, int level, int name, void* value, socklen_t* size) = 0;
  // if_nametoindex: the index (> 0), or -ENODEV when there is no such interface.
  virtual int interface_index(const std::string& name) = 0;
  // SIOCGIFFLAGS through `fd`: 1 when IFF_UP is set, 0 when not, or -errno.
  virtual int interface_up(int fd, const std::string& name) = 0;
  // bind() to a struct sockaddr_can for `ifindex`.
  virtual int bind_can(int fd, int ifindex) = 0;
  // recvmmsg(fd, messages, count, MSG_DONTWAIT, nullptr): messages filled, or -errno.
  virtual int receive(int fd, struct mmsghdr* messages, unsigned int count) = 0;
  // send(fd, data, size, MSG_DONTWAIT): bytes sent, or -errno.
  virtual ssize_t send(int fd, const void* data, size_t size) = 0;
  // poll(fds, count, timeout_ms); count 0 is a plain wait.
  virtual int poll(struct pollfd* fds, nfds_t count, int timeout_ms) = 0;

 protected:
  SocketOps() = default;
  SocketOps(const SocketOps&) = default;
  SocketOps& operator=(const SocketOps&) = default;
};

// The real system calls. Stateless; lives for the whole program.
SocketOps& system_socket_ops() noexcept;

}  // namespace pmu::transport
