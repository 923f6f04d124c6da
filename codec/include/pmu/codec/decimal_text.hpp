#pragma once
// The spellings of numbers a file of pmu-dds takes (interface.md 4.1, 4.6): plain decimal only.
// YAML 1.1 reads 010 as octal 8 and 0x10 as 16, and strtod takes 0x18 as 24, so a number in
// any other spelling could silently name another address or voltage; both the service's
// config and a PMU's configuration file refuse it with these.

#include <string_view>

namespace pmu::codec {

// -?(0|[1-9][0-9]*): an integer. Not 010, 0x10, 0o10, 1e1, +5, 1.0 or " 5".
bool is_plain_decimal(std::string_view text) noexcept;

// -?(0|[1-9][0-9]*)(\.[0-9]+)?: an integer or a decimal fraction (24.0, 0.5, -3). Not 0x18,
// 024, 2.4e1, .5, 5., +24, inf or nan.
bool is_plain_decimal_number(std::string_view text) noexcept;

}  // namespace pmu::codec
