#include "pmuctl/call/option_values.hpp"

#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cctype>
#include <cstdlib>

namespace pmu::tools {
namespace {

std::string quoted(std::string_view option, std::string_view text) {
  // An option value from the command line is echoed short: a 1 MB argument is not repeated.
  constexpr std::size_t kShown = 32;
  std::string t(text.substr(0, kShown));
  if (text.size() > kShown) t += "...";
  return std::string(option) + " '" + t + "'";
}

}  // namespace

Parsed<double> parse_seconds(std::string_view option, std::string_view text) {
  const std::string s(text);
  char* end = nullptr;
  errno = 0;
  const double v = s.empty() ? std::nan("") : std::strtod(s.c_str(), &end);
  char max[32];
  std::snprintf(max, sizeof max, "%g", kMaxSeconds);
  const std::string range = " is not a number of seconds (more than 0, at most " + std::string(max) + ")";
  if (s.empty() || std::isspace(static_cast<unsigned char>(s.front())) || *end != '\0' || errno == ERANGE ||
      !std::isfinite(v) || v <= 0 || v > kMaxSeconds)
    return quoted(option, text) + range;
  return v;
}

Parsed<long> parse_count(std::string_view option, std::string_view text) {
  const std::string s(text);
  char* end = nullptr;
  errno = 0;
  const long v = s.empty() ? 0 : std::strtol(s.c_str(), &end, 10);
  if (s.empty() || *end != '\0' || errno == ERANGE || v < 1 || v > kMaxCount || s.front() == '+' ||
      std::isspace(static_cast<unsigned char>(s.front())))
    return quoted(option, text) + " is not a whole number 1.." + std::to_string(kMaxCount);
  return v;
}

}  // namespace pmu::tools
