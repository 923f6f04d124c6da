#include "pmu/codec/decimal_text.hpp"

namespace pmu::codec {
namespace {

bool digit(char c) noexcept { return c >= '0' && c <= '9'; }

// Past the integer part -?(0|[1-9][0-9]*) at the start of `text`; npos when there is none.
std::size_t integer_end(std::string_view text) noexcept {
  std::size_t i = !text.empty() && text[0] == '-' ? 1 : 0;
  if (i == text.size() || !digit(text[i])) return std::string_view::npos;
  if (text[i] == '0') return i + 1;
  while (i < text.size() && digit(text[i])) ++i;
  return i;
}

}  // namespace

bool is_plain_decimal(std::string_view text) noexcept { return integer_end(text) == text.size(); }

bool is_plain_decimal_number(std::string_view text) noexcept {
  std::size_t i = integer_end(text);
  if (i == text.size()) return true;
  if (i == std::string_view::npos || text[i] != '.' || i + 1 == text.size()) return false;
  for (++i; i < text.size(); ++i)
    if (!digit(text[i])) return false;
  return true;
}

}  // namespace pmu::codec
