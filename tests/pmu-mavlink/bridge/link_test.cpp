// The two endpoints on real descriptors: the serial endpoint over a pty pair (the test holds
// the master side, as an autopilot's TELEM port would), the UDP endpoint against a socket on
// loopback playing the ground station.
#include <arpa/inet.h>
#include <fcntl.h>
#include <netinet/in.h>
#include <poll.h>
#include <pty.h>
#include <sys/socket.h>
#include <unistd.h>

#include <gtest/gtest.h>

#include "link/endpoint_address.hpp"
#include "link/serial_endpoint.hpp"
#include "link/udp_endpoint.hpp"
#include "pmu/transport/unique_fd.hpp"

namespace pmu::mavlink_bridge {
namespace {

using pmu::transport::UniqueFd;
using Bytes = std::vector<std::uint8_t>;

bool readable(int fd) {
  pollfd p{fd, POLLIN, 0};
  return ::poll(&p, 1, 5000) == 1;  // a bound on a hang, not a timed assertion
}

TEST(EndpointAddress, Udp) {
  struct Case {
    const char* text;
    bool ok;
    const char* host;
    int port;
  };
  const Case cases[] = {{"127.0.0.1:14550", true, "127.0.0.1", 14550},
                        {"gcs.local:1", true, "gcs.local", 1},
                        {"[::1]:14550", true, "::1", 14550},
                        {"::1:14550", false, "", 0},
                        {"127.0.0.1", false, "", 0},
                        {":14550", false, "", 0},
                        {"host:0", false, "", 0},
                        {"host:65536", false, "", 0},
                        {"host:port", false, "", 0}};
  for (const auto& c : cases) {
    const auto r = parse_udp_address(c.text);
    ASSERT_EQ(std::holds_alternative<UdpAddress>(r), c.ok) << c.text;
    if (c.ok) {
      EXPECT_EQ(std::get<UdpAddress>(r).host, c.host);
      EXPECT_EQ(std::get<UdpAddress>(r).port, c.port);
    } else {
      EXPECT_NE(std::get<std::string>(r).find(c.text), std::string::npos) << "the error names the value";
    }
  }
}

TEST(EndpointAddress, Serial) {
  const auto ok = parse_serial_address("/dev/ttyAMA0:57600");
  ASSERT_TRUE(std::holds_alternative<SerialAddress>(ok));
  EXPECT_EQ(std::get<SerialAddress>(ok).device, "/dev/ttyAMA0");
  EXPECT_EQ(std::get<SerialAddress>(ok).baud, 57600U);
  for (const char* bad : {"/dev/ttyAMA0", "/dev/ttyAMA0:57601", ":57600", "/dev/ttyS0:fast"})
    EXPECT_TRUE(std::holds_alternative<std::string>(parse_serial_address(bad))) << bad;
}

TEST(SerialEndpoint, BytesBothWaysOverPty) {
  int master = -1;
  int slave = -1;
  char name[256] = {};
  ASSERT_EQ(::openpty(&master, &slave, name, nullptr, nullptr), 0);
  UniqueFd m(master);
  UniqueFd s(slave);  // held open so the master does not see a hang-up
  SerialEndpoint link(SerialAddress{name, 57600});
  const Bytes frame{0xFD, 0x09, 0x00, 0x00, 0x01, 0x01, 0xB4, 0x00, 0x00, 0x00, 0x0A, 0x0D};
  link.send(frame);
  EXPECT_EQ(link.counters().frames_out, 1U);
  Bytes got(64);
  ASSERT_TRUE(readable(m.get()));
  const ssize_t n = ::read(m.get(), got.data(), got.size());
  ASSERT_EQ(n, static_cast<ssize_t>(frame.size()));
  got.resize(static_cast<std::size_t>(n));
  EXPECT_EQ(got, frame) << "raw: no byte changed (no CR/LF mapping)";

  const Bytes in{0x0D, 0x0A, 0xFD, 0x11, 0x00};
  ASSERT_EQ(::write(m.get(), in.data(), in.size()), static_cast<ssize_t>(in.size()));
  ASSERT_TRUE(readable(link.fd()));
  Bytes read;
  EXPECT_TRUE(link.read_available(read));
  EXPECT_EQ(read, in);
  EXPECT_EQ(link.counters().bytes_in, in.size());
}

TEST(SerialEndpoint, RefusesWhatIsNotATerminal) {
  EXPECT_THROW(SerialEndpoint(SerialAddress{"/dev/null", 57600}), LinkError);
  EXPECT_THROW(SerialEndpoint(SerialAddress{"/nonexistent/ttyX", 57600}), LinkError);
}

TEST(UdpEndpoint, SendsToTheAddressAndTakesItsAnswers) {
  UniqueFd gcs(::socket(AF_INET, SOCK_DGRAM | SOCK_CLOEXEC, 0));
  ASSERT_TRUE(gcs);
  sockaddr_in at{};
  at.sin_family = AF_INET;
  at.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  ASSERT_EQ(::bind(gcs.get(), reinterpret_cast<sockaddr*>(&at), sizeof at), 0);
  socklen_t len = sizeof at;
  ASSERT_EQ(::getsockname(gcs.get(), reinterpret_cast<sockaddr*>(&at), &len), 0);

  UdpEndpoint link(UdpAddress{"127.0.0.1", ntohs(at.sin_port)});
  const Bytes frame{0xFD, 1, 2, 3};
  link.send(frame);
  Bytes got(64);
  sockaddr_in from{};
  socklen_t from_len = sizeof from;
  ASSERT_TRUE(readable(gcs.get()));
  const ssize_t n = ::recvfrom(gcs.get(), got.data(), got.size(), 0, reinterpret_cast<sockaddr*>(&from), &from_len);
  ASSERT_EQ(n, 4);
  got.resize(4);
  EXPECT_EQ(got, frame);

  // The ground station answers to where the datagram came from: the endpoint's one socket.
  const Bytes answer{0xFD, 9, 8};
  ASSERT_EQ(::sendto(gcs.get(), answer.data(), answer.size(), 0, reinterpret_cast<sockaddr*>(&from), from_len), 3);
  ASSERT_TRUE(readable(link.fd()));
  Bytes read;
  EXPECT_TRUE(link.read_available(read));
  EXPECT_EQ(read, answer);
}

TEST(UdpEndpoint, NoListenerIsCountedNotFatal) {
  // A port nobody listens on: bind one, learn it, close it.
  sockaddr_in at{};
  {
    UniqueFd tmp(::socket(AF_INET, SOCK_DGRAM | SOCK_CLOEXEC, 0));
    at.sin_family = AF_INET;
    at.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
    ASSERT_EQ(::bind(tmp.get(), reinterpret_cast<sockaddr*>(&at), sizeof at), 0);
    socklen_t len = sizeof at;
    ASSERT_EQ(::getsockname(tmp.get(), reinterpret_cast<sockaddr*>(&at), &len), 0);
  }
  UdpEndpoint link(UdpAddress{"127.0.0.1", ntohs(at.sin_port)});
  link.send(Bytes{0xFD});
  link.send(Bytes{0xFD});  // the ICMP error of the first is reported on this call or a read
  Bytes read;
  EXPECT_TRUE(link.read_available(read));
  EXPECT_TRUE(read.empty());
  EXPECT_GE(link.counters().send_failures + link.counters().read_failures, 1U);
}

TEST(UdpEndpoint, UnresolvableHostIsAStartUpError) {
  try {
    UdpEndpoint link(UdpAddress{"no-such-host.invalid", 14550});
    FAIL() << "no error";
  } catch (const LinkError& e) {
    EXPECT_NE(std::string(e.what()).find("no-such-host.invalid"), std::string::npos);
  }
}

}  // namespace
}  // namespace pmu::mavlink_bridge
