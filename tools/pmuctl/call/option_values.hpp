#pragma once
// pmuctl's numeric option values, parsed once from their text by total functions: CLI11's
// own checks accept "nan" for --timeout, take 1e10 s (whose deadline overflows the clock),
// and describe --count's range with DBL_MAX in 309 digits.
//
//   parse_seconds("2.5")  -> 2.5            parse_seconds("nan") -> error "... not a number of seconds ..."
//   parse_count("20")     -> 20             parse_count("0")     -> error "... a whole number 1.."

#include <string>
#include <string_view>
#include <variant>

namespace pmu::tools {

// The longest wait any verb accepts (a week): longer is surely a typing error, and every
// deadline computed from it (steady_clock + seconds, an expiry in ns since 1970) stays far
// inside the clocks' range.
inline constexpr double kMaxSeconds = 7 * 24 * 3600.0;
inline constexpr long kMaxCount = 1000000000L;

// A value, or the reason it is refused, naming the option and the text.
template <class T>
using Parsed = std::variant<T, std::string>;

Parsed<double> parse_seconds(std::string_view option, std::string_view text);
Parsed<long> parse_count(std::string_view option, std::string_view text);

}  // namespace pmu::tools
