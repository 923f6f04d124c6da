#include "pmuctl/decode/json_line.hpp"

#include <cstring>
#include <charconv>
#include <cmath>
#include <nlohmann/json.hpp>

namespace pmu::tools {
namespace {

// Printable ASCII other than '"' and '\\' is written as it is; anything else needs escaping.
bool plain_ascii(std::string_view v) {
  for (const char c : v) {
    const auto u = static_cast<unsigned char>(c);
    if (u < 0x20 || u >= 0x7F || c == '"' || c == '\\') return false;
  }
  return true;
}

// Escapes, UTF-8 and invalid bytes (replaced by U+FFFD): nlohmann decides, as it did before.
std::string escaped_by_nlohmann(std::string_view v) {
  return nlohmann::json(std::string(v)).dump(-1, ' ', false, nlohmann::json::error_handler_t::replace);
}

}  // namespace

void JsonLine::put(const char* p, std::size_t n) {
  if (used_ + n > sizeof buf_) {
    flush();
    if (n > sizeof buf_) {
      out_.append(p, n);
      return;
    }
  }
  std::memcpy(buf_ + used_, p, n);
  used_ += n;
}

void JsonLine::flush() {
  out_.append(buf_, used_);
  used_ = 0;
}

void JsonLine::key(std::string_view k) {
  if (!first_) put(",", 1);
  first_ = false;
  put("\"", 1);
  put(k);
  put("\":", 2);
}

JsonLine& JsonLine::number(std::string_view k, double v) {
  key(k);
  if (!std::isfinite(v)) {
    put("null", 4);
    return *this;
  }
  char buf[64];
  char* end = nlohmann::detail::to_chars(buf, buf + sizeof buf, v);
  put(buf, static_cast<std::size_t>(end - buf));
  return *this;
}

JsonLine& JsonLine::integer(std::string_view k, std::int64_t v) {
  key(k);
  char buf[24];
  const auto r = std::to_chars(buf, buf + sizeof buf, v);
  put(buf, static_cast<std::size_t>(r.ptr - buf));
  return *this;
}

JsonLine& JsonLine::boolean(std::string_view k, bool v) {
  key(k);
  if (v)
    put("true", 4);
  else
    put("false", 5);
  return *this;
}

JsonLine& JsonLine::null(std::string_view k) {
  key(k);
  put("null", 4);
  return *this;
}

JsonLine& JsonLine::string(std::string_view k, std::string_view v) {
  key(k);
  if (plain_ascii(v)) {
    put("\"", 1);
    put(v);
    put("\"", 1);
  } else {
    put(escaped_by_nlohmann(v));
  }
  return *this;
}

JsonLine& JsonLine::begin_object(std::string_view k) {
  key(k);
  put("{", 1);
  first_ = true;
  return *this;
}

JsonLine& JsonLine::end_object() {
  put("}", 1);
  first_ = false;
  return *this;
}

void JsonLine::end() {
  put("}\n", 2);
  flush();
}

}  // namespace pmu::tools
