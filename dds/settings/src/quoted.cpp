#include "pmu/dds_settings/quoted.hpp"

#include <cstdio>

namespace pmu::dds {
namespace {

constexpr std::size_t kWhole = 32;   // shown whole up to this many bytes
constexpr std::size_t kPrefix = 24;  // else this many, at most

bool continuation(unsigned char ch) { return (ch & 0xC0) == 0x80; }

// The length of the UTF-8 sequence at `at`, or 0 when none starts there.
std::size_t sequence_length(std::string_view s, std::size_t at) {
  const auto lead = static_cast<unsigned char>(s[at]);
  const std::size_t n = lead < 0x80             ? 1
                        : (lead & 0xE0) == 0xC0 ? 2
                        : (lead & 0xF0) == 0xE0 ? 3
                        : (lead & 0xF8) == 0xF0 ? 4
                                                : 0;
  if (n == 0 || at + n > s.size()) return 0;
  for (std::size_t i = 1; i < n; ++i)
    if (!continuation(static_cast<unsigned char>(s[at + i]))) return 0;
  return n;
}

}  // namespace

std::string quoted(std::string_view value) {
  const std::size_t limit = value.size() <= kWhole ? value.size() : kPrefix;
  std::string out = "'";
  for (std::size_t i = 0; i < limit;) {
    const auto ch = static_cast<unsigned char>(value[i]);
    const std::size_t n = sequence_length(value, i);
    if (n > 1 && i + n > limit) break;  // never half a character
    if (n == 0 || ch < 0x20 || ch == 0x7F) {
      char buf[8];
      std::snprintf(buf, sizeof buf, "\\x%02X", ch);
      out += buf;
      ++i;
    } else {
      out.append(value.substr(i, n));
      i += n;
    }
  }
  out += "'";
  if (limit < value.size()) out.insert(out.size() - 1, "...").append(" (" + std::to_string(value.size()) + " bytes)");
  return out;
}

std::string character_at(std::string_view s, std::size_t at) {
  const auto ch = static_cast<unsigned char>(s[at]);
  const std::size_t n = sequence_length(s, at);
  if (n == 0 || ch < 0x20 || ch == 0x7F) {
    char buf[16];
    std::snprintf(buf, sizeof buf, "byte 0x%02X", ch);
    return buf;
  }
  return "'" + std::string(s.substr(at, n)) + "'";
}

}  // namespace pmu::dds
