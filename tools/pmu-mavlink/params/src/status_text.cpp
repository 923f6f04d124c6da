#include "pmu/mavlink_params/status_text.hpp"

#include <string>

namespace pmu::mavlink_params {

std::vector<mavlink::Statustext> status_text(std::uint8_t severity, std::string_view text, std::uint16_t id) {
  constexpr std::size_t n = mavlink::Statustext::kTextLength;
  std::string clean;
  for (const char c : text) clean += (c >= 0x20 && c < 0x7F) ? c : '?';
  // Cut so that the last chunk is not full: kMaxChunks messages, the terminator included.
  if (clean.size() >= n * kMaxChunks) clean = clean.substr(0, n * kMaxChunks - 4) + "...";
  std::vector<mavlink::Statustext> out;
  if (clean.size() <= n) {
    out.push_back({severity, clean, 0, 0});
    return out;
  }
  for (std::size_t at = 0, seq = 0; at < clean.size(); at += n, ++seq)
    out.push_back({severity, clean.substr(at, n), id == 0 ? std::uint16_t{1} : id, static_cast<std::uint8_t>(seq)});
  // A text of whole chunks ends with an empty one, so a reader knows the last has come
  // (STATUSTEXT: "the final chunk has a NULL terminator").
  if (clean.size() % n == 0) out.push_back({severity, "", out.back().id, static_cast<std::uint8_t>(out.size())});
  return out;
}

}  // namespace pmu::mavlink_params
