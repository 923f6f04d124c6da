#include "pmu/codec/candump.hpp"

namespace pmu::codec {
namespace {

using Parsed = Result<CandumpLine, CandumpError>;

Parsed fail(std::string_view reason) noexcept { return Unexpected{CandumpError{reason}}; }

bool is_space(char c) noexcept { return c == ' ' || c == '\t' || c == '\r' || c == '\n'; }

int hex_value(char c) noexcept {
  if (c >= '0' && c <= '9') return c - '0';
  if (c >= 'a' && c <= 'f') return c - 'a' + 10;
  if (c >= 'A' && c <= 'F') return c - 'A' + 10;
  return -1;
}

std::string_view trim(std::string_view s) noexcept {
  while (!s.empty() && is_space(s.front())) s.remove_prefix(1);
  while (!s.empty() && is_space(s.back())) s.remove_suffix(1);
  return s;
}

// Splits off the next whitespace-delimited token.
std::string_view next_token(std::string_view& s) noexcept {
  while (!s.empty() && is_space(s.front())) s.remove_prefix(1);
  std::size_t n = 0;
  while (n < s.size() && !is_space(s[n])) ++n;
  const std::string_view tok = s.substr(0, n);
  s.remove_prefix(n);
  return tok;
}

bool parse_id(std::string_view text, CanFrame& f) noexcept {
  if (text.size() != 3 && text.size() != 8) return false;
  std::uint32_t id = 0;
  for (char c : text) {
    const int v = hex_value(c);
    if (v < 0) return false;
    id = (id << 4) | static_cast<std::uint32_t>(v);
  }
  f.extended = text.size() == 8;
  if (f.extended ? id > kMaxExtendedId : id > kMaxStandardId) return false;
  f.id = id;
  return true;
}

// "(1700000000.123456)" -> seconds, microseconds. Digits after the dot beyond six are cut.
bool parse_time(std::string_view tok, CandumpLine& out) noexcept {
  if (tok.size() < 3 || tok.front() != '(' || tok.back() != ')') return false;
  tok = tok.substr(1, tok.size() - 2);
  const auto dot = tok.find('.');
  if (dot == std::string_view::npos || dot == 0 || dot > 18) return false;
  std::int64_t sec = 0;
  for (std::size_t i = 0; i < dot; ++i) {
    if (tok[i] < '0' || tok[i] > '9') return false;
    sec = sec * 10 + (tok[i] - '0');
  }
  std::uint32_t usec = 0;
  std::size_t digits = 0;
  for (std::size_t i = dot + 1; i < tok.size(); ++i) {
    if (tok[i] < '0' || tok[i] > '9') return false;
    if (digits < 6) usec = usec * 10 + static_cast<std::uint32_t>(tok[i] - '0');
    ++digits;
  }
  if (digits == 0) return false;
  for (; digits < 6; ++digits) usec *= 10;
  out.has_time = true;
  out.seconds = sec;
  out.microseconds = usec;
  return true;
}

Parsed parse_log_frame(std::string_view tok, CandumpLine out) noexcept {
  const auto hash = tok.find('#');
  if (hash == std::string_view::npos) return fail("missing '#' between id and data");
  if (!parse_id(tok.substr(0, hash), out.frame)) return fail("id must be 3 (standard) or 8 (extended) hex digits");
  std::string_view data = tok.substr(hash + 1);
  if (!data.empty() && data.front() == '#') return fail("CAN FD frame: the PMU uses classic CAN");
  if (!data.empty() && (data.front() == 'R' || data.front() == 'r')) {
    out.frame.remote = true;
    data.remove_prefix(1);
    if (data.size() == 1 && data[0] >= '0' && data[0] <= '8')
      out.frame.length = static_cast<std::uint8_t>(data[0] - '0');
    else if (!data.empty())
      return fail("bad remote frame length");
    return out;
  }
  std::uint8_t n = 0;
  std::size_t i = 0;
  while (i < data.size()) {
    if (data[i] == '.') {  // cansend allows dots between bytes
      ++i;
      continue;
    }
    if (i + 1 >= data.size()) return fail("odd number of hex digits in data");
    const int hi = hex_value(data[i]), lo = hex_value(data[i + 1]);
    if (hi < 0 || lo < 0) return fail("data is not hex");
    if (n == kMaxDataLength) return fail("more than 8 data bytes");
    out.frame.data[n++] = static_cast<std::uint8_t>((hi << 4) | lo);
    i += 2;
  }
  out.frame.length = n;
  return out;
}

Parsed parse_screen_frame(std::string_view id_tok, std::string_view rest, CandumpLine out) noexcept {
  if (!parse_id(id_tok, out.frame)) return fail("id must be 3 (standard) or 8 (extended) hex digits");
  const std::string_view len_tok = next_token(rest);
  if (len_tok.size() < 3 || len_tok.front() != '[' || len_tok.back() != ']') return fail("missing [length]");
  unsigned len = 0;
  for (std::size_t i = 1; i + 1 < len_tok.size(); ++i) {
    if (len_tok[i] < '0' || len_tok[i] > '9' || len > 64) return fail("bad [length]");
    len = len * 10 + static_cast<unsigned>(len_tok[i] - '0');
  }
  if (len > kMaxDataLength) return fail("length above 8: CAN FD frames are not supported");
  out.frame.length = static_cast<std::uint8_t>(len);
  rest = trim(rest);
  if (rest.substr(0, 14) == "remote request") {
    out.frame.remote = true;
    return out;
  }
  for (unsigned i = 0; i < len; ++i) {
    const std::string_view b = next_token(rest);
    if (b.empty()) return fail("fewer data bytes than [length]");
    const int hi = b.size() == 2 ? hex_value(b[0]) : -1, lo = b.size() == 2 ? hex_value(b[1]) : -1;
    if (hi < 0 || lo < 0) return fail("data byte is not two hex digits");
    out.frame.data[i] = static_cast<std::uint8_t>((hi << 4) | lo);
  }
  // candump -a appends the bytes as ASCII in quotes; anything else is an error.
  rest = trim(rest);
  if (!rest.empty() && rest.front() != '\'') return fail("more data bytes than [length]");
  return out;
}

}  // namespace

Result<CandumpLine, CandumpError> parse_candump_line(std::string_view line) noexcept {
  std::string_view rest = trim(line);
  if (rest.empty()) return fail("empty line");
  CandumpLine out;
  std::string_view tok = next_token(rest);
  if (tok.front() == '(') {
    if (!parse_time(tok, out)) return fail("bad timestamp: expected (seconds.microseconds)");
    tok = next_token(rest);
  }
  if (tok.empty()) return fail("missing interface");
  // A frame where the interface belongs ("(1.0) 123#00"): the interface is what is missing.
  if (tok.find('#') != std::string_view::npos) return fail("missing interface");
  out.interface = tok;
  const std::string_view frame_tok = next_token(rest);
  if (frame_tok.empty()) return fail("missing frame");
  if (frame_tok.find('#') != std::string_view::npos) {
    // Log form: nothing may follow but candump's optional direction flag (T or R).
    const std::string_view extra = next_token(rest);
    if (!(extra.empty() || ((extra == "T" || extra == "R") && trim(rest).empty())))
      return fail("unexpected text after the frame");
    return parse_log_frame(frame_tok, out);
  }
  return parse_screen_frame(frame_tok, rest, out);
}

}  // namespace pmu::codec
