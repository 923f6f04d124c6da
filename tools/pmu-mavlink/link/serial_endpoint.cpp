#include "link/serial_endpoint.hpp"

#include <fcntl.h>
#include <sys/ioctl.h>
#include <termios.h>
#include <unistd.h>

#include <array>
#include <cerrno>
#include <cstring>

namespace pmu::mavlink_bridge {

namespace {

speed_t speed_of(std::uint32_t baud) {
  switch (baud) {
    case 9600: return B9600;
    case 19200: return B19200;
    case 38400: return B38400;
    case 57600: return B57600;
    case 115200: return B115200;
    case 230400: return B230400;
    case 460800: return B460800;
    case 500000: return B500000;
    case 921600: return B921600;
    default: break;
  }
  return B0;
}

}  // namespace

SerialEndpoint::SerialEndpoint(const SerialAddress& address)
    : description_("serial " + address.device + " " + std::to_string(address.baud)) {
  fd_.reset(::open(address.device.c_str(), O_RDWR | O_NOCTTY | O_NONBLOCK | O_CLOEXEC));
  if (!fd_) throw LinkError("cannot open " + description_ + ": " + std::strerror(errno));
  termios t{};
  if (::tcgetattr(fd_.get(), &t) != 0)
    throw LinkError("cannot use " + description_ + ": " + std::strerror(errno) + " (not a serial port?)");
  const speed_t speed = speed_of(address.baud);
  if (speed == B0) throw LinkError("cannot use " + description_ + ": baud rate not supported");
  ::cfmakeraw(&t);
  t.c_cflag |= CLOCAL | CREAD;
  t.c_cflag &= ~static_cast<tcflag_t>(CRTSCTS | CSTOPB);
  t.c_cc[VMIN] = 0;
  t.c_cc[VTIME] = 0;
  if (::cfsetispeed(&t, speed) != 0 || ::cfsetospeed(&t, speed) != 0 || ::tcsetattr(fd_.get(), TCSANOW, &t) != 0)
    throw LinkError("cannot configure " + description_ + ": " + std::strerror(errno));
  ::tcflush(fd_.get(), TCIOFLUSH);
}

bool SerialEndpoint::read_available(std::vector<std::uint8_t>& out) {
  std::array<std::uint8_t, 4096> buffer{};
  for (;;) {
    const ssize_t n = ::read(fd_.get(), buffer.data(), buffer.size());
    if (n > 0) {
      out.insert(out.end(), buffer.begin(), buffer.begin() + n);
      counters_.bytes_in += static_cast<std::uint64_t>(n);
      continue;
    }
    if (n < 0 && errno == EINTR) continue;
    if (n < 0 && (errno == EAGAIN || errno == EWOULDBLOCK)) return true;
    if (n == 0) return true;  // VMIN 0: nothing waiting
    ++counters_.read_failures;
    return errno != EIO && errno != ENXIO && errno != ENODEV;  // the device went away
  }
}

void SerialEndpoint::send(const std::vector<std::uint8_t>& frame) {
  // What the port can take now without blocking: whole frame or none.
  int queued = 0;
  int room = -1;
  if (::ioctl(fd_.get(), TIOCOUTQ, &queued) == 0) {
    // The kernel's tty buffer is 4096 bytes; keeping a frame's worth clear of it means a
    // write of a whole frame is not cut by EAGAIN half-way.
    room = 4096 - queued;
  }
  if (room >= 0 && room < static_cast<int>(frame.size())) {
    ++counters_.send_failures;
    return;
  }
  const ssize_t n = ::write(fd_.get(), frame.data(), frame.size());
  if (n == static_cast<ssize_t>(frame.size())) {
    counters_.bytes_out += frame.size();
    ++counters_.frames_out;
  } else {
    ++counters_.send_failures;
  }
}

}  // namespace pmu::mavlink_bridge
