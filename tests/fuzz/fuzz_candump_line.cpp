// libFuzzer target: arbitrary bytes -> parse_candump_line. The parser must never crash or read
// past the string_view, and a line it accepts must hold a classic CAN frame that the decoders
// take, and that prints back (in either candump form) to a line parsing to the same frame.
//
// The whole input is parsed as one line, then each '\n'-separated piece on its own, so a
// corpus file can hold several lines.
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <string>
#include <string_view>

#include "pmu/codec/candump.hpp"
#include "pmu/codec/canopen.hpp"
#include "pmu/codec/decode.hpp"

namespace {

namespace codec = pmu::codec;

void require(bool ok) {
  if (!ok) __builtin_trap();
}

bool is_space(char c) { return c == ' ' || c == '\t' || c == '\r' || c == '\n'; }

std::string hex_id(const codec::CanFrame& f) {
  char buf[16];
  std::snprintf(buf, sizeof buf, f.extended ? "%08X" : "%03X", static_cast<unsigned>(f.id));
  return buf;
}

std::string hex_byte(std::uint8_t b) {
  char buf[4];
  std::snprintf(buf, sizeof buf, "%02X", static_cast<unsigned>(b));
  return buf;
}

std::string timestamp(const codec::CandumpLine& c) {
  char buf[48];
  std::snprintf(buf, sizeof buf, "(%lld.%06u) ", static_cast<long long>(c.seconds),
                static_cast<unsigned>(c.microseconds));
  return buf;
}

// candump -L: "(s.us) iface 123#0102" / "123#R" / "123#R3"
std::string log_form(const codec::CandumpLine& c) {
  std::string s = c.has_time ? timestamp(c) : std::string();
  s += std::string(c.interface) + " " + hex_id(c.frame) + "#";
  if (c.frame.remote) {
    s += "R";
    if (c.frame.length > 0) s += static_cast<char>('0' + c.frame.length);
  } else {
    for (std::size_t i = 0; i < c.frame.length; ++i) s += hex_byte(c.frame.data[i]);
  }
  return s;
}

// candump: "  iface  123   [2]  01 02" / "[n]  remote request"
std::string screen_form(const codec::CandumpLine& c) {
  std::string s = c.has_time ? " " + timestamp(c) : std::string();
  s += "  " + std::string(c.interface) + "  " + hex_id(c.frame) + "   [" + std::to_string(c.frame.length) + "] ";
  if (c.frame.remote) {
    s += " remote request";
  } else {
    for (std::size_t i = 0; i < c.frame.length; ++i) s += " " + hex_byte(c.frame.data[i]);
  }
  return s;
}

void require_same(const codec::CandumpLine& a, const std::string& text) {
  const auto r = codec::parse_candump_line(text);
  require(r.ok());
  const codec::CandumpLine& b = r.value();
  require(a.frame == b.frame);
  require(a.has_time == b.has_time && a.seconds == b.seconds && a.microseconds == b.microseconds);
  require(a.interface == b.interface);
}

void check_line(std::string_view line) {
  const auto r = codec::parse_candump_line(line);
  require(r.ok() == static_cast<bool>(r));
  if (!r.ok()) {
    require(!r.error().reason.empty());
    return;
  }
  const codec::CandumpLine& c = r.value();
  const codec::CanFrame& f = c.frame;
  require(f.length <= codec::kMaxDataLength);
  require(f.extended ? f.id <= codec::kMaxExtendedId : f.id <= codec::kMaxStandardId);
  require(c.microseconds < 1000000u && c.seconds >= 0);
  require(c.has_time || (c.seconds == 0 && c.microseconds == 0));
  require(!c.interface.empty());
  require(c.interface.data() >= line.data() && c.interface.data() + c.interface.size() <= line.data() + line.size());
  for (char ch : c.interface) require(!is_space(ch));

  // The frame goes on to the decoders as a frame read from a bus would.
  const auto pmu = codec::decode(f);
  if (pmu.ok()) require(pmu->address == (f.id & 0xFFFFu) && f.extended && !f.remote);
  const auto canopen = codec::canopen::decode(f);
  if (canopen.ok()) require(!f.extended && canopen->cob_id == f.id);

  // Printed back in either form, it parses to the same thing.
  require_same(c, log_form(c));
  require_same(c, screen_form(c));
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  // string_view over the fuzzer's buffer: ASan catches any read past it.
  const std::string_view text(reinterpret_cast<const char*>(data), size);  // NOLINT: bytes as text
  check_line(text);
  std::size_t start = 0;
  while (start <= text.size()) {
    const std::size_t end = text.find('\n', start);
    const std::size_t stop = end == std::string_view::npos ? text.size() : end;
    check_line(text.substr(start, stop - start));
    if (end == std::string_view::npos) break;
    start = end + 1;
  }
  return 0;
}
