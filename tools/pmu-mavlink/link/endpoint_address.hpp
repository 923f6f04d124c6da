#pragma once
// The values of --udp HOST:PORT and --serial DEVICE:BAUD (and the config's `udp:` and
// `serial:`), typed once by total functions: a value or the reason it is not one.
#include <cstdint>
#include <string>
#include <variant>

namespace pmu::mavlink_bridge {

struct UdpAddress {
  std::string host;  // a name, an IPv4 address, or an IPv6 address written in [ ]
  std::uint16_t port = 0;
};

struct SerialAddress {
  std::string device;
  std::uint32_t baud = 0;
};

// "HOST:PORT", "[IPV6]:PORT"; port 1..65535.
std::variant<UdpAddress, std::string> parse_udp_address(const std::string& text);
// "DEVICE:BAUD", the baud one termios knows (9600 ... 921600).
std::variant<SerialAddress, std::string> parse_serial_address(const std::string& text);

}  // namespace pmu::mavlink_bridge
