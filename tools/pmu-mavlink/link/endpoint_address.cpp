#include "link/endpoint_address.hpp"

#include <algorithm>
#include <array>
#include <cctype>

namespace pmu::mavlink_bridge {

namespace {

// Baud rates termios names (B9600 ...) that autopilot TELEM ports use.
constexpr std::array<std::uint32_t, 9> kBauds{9600, 19200, 38400, 57600, 115200, 230400, 460800, 500000, 921600};

bool all_digits(const std::string& s) {
  return !s.empty() && s.size() <= 9 &&
         std::all_of(s.begin(), s.end(), [](unsigned char c) { return std::isdigit(c); });
}

}  // namespace

std::variant<UdpAddress, std::string> parse_udp_address(const std::string& text) {
  const auto colon = text.rfind(':');
  if (colon == std::string::npos) return "'" + text + "' is not HOST:PORT";
  std::string host = text.substr(0, colon);
  const std::string port = text.substr(colon + 1);
  if (host.size() >= 2 && host.front() == '[' && host.back() == ']') {
    host = host.substr(1, host.size() - 2);
  } else if (host.find(':') != std::string::npos) {
    return "'" + text + "': write an IPv6 address in brackets, [ADDRESS]:PORT";
  }
  if (host.empty()) return "'" + text + "' has no host before the port";
  if (!all_digits(port) || std::stoul(port) == 0 || std::stoul(port) > 65535)
    return "'" + text + "': the port must be 1..65535";
  return UdpAddress{host, static_cast<std::uint16_t>(std::stoul(port))};
}

std::variant<SerialAddress, std::string> parse_serial_address(const std::string& text) {
  const auto colon = text.rfind(':');
  if (colon == std::string::npos || colon == 0) return "'" + text + "' is not DEVICE:BAUD";
  const std::string baud = text.substr(colon + 1);
  if (!all_digits(baud) ||
      std::find(kBauds.begin(), kBauds.end(), static_cast<std::uint32_t>(std::stoul(baud))) == kBauds.end())
    return "'" + text +
           "': the baud rate must be one of 9600, 19200, 38400, 57600, 115200, 230400, 460800, 500000, 921600";
  return SerialAddress{text.substr(0, colon), static_cast<std::uint32_t>(std::stoul(baud))};
}

}  // namespace pmu::mavlink_bridge
