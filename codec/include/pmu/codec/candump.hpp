#pragma once
// Parsing of the two text forms can-utils' candump writes, so captured bus logs can be
// decoded offline. Pure text in, frame out: no I/O, no exceptions, never reads past the
// string_view.
//
// Log form (candump -L), as in the can-utils lib.h examples:
//   (1700000000.000000) can0 1E000001#FA0A          extended id (8 hex digits), 2 bytes
//   (1700000000.000000) can0 202#0102030405060708  standard id (3 hex digits)
//   (1700000000.000000) can0 1E240001#              extended id, length 0
//   (1700000000.000000) can0 123#R                  remote frame
// Screen form (candump, optionally with -ta absolute timestamps):
//   "  can0  1E000001   [2]  FA 0A"
//   " (1700000000.000000)  can0  202   [8]  01 02 03 04 05 06 07 08"
//   "  can0  123   [0]  remote request"
// CAN FD frames ("##" or lengths above 8) are refused: the PMU is a classic CAN device.

#include <cstdint>
#include <string_view>

#include "pmu/codec/can_frame.hpp"
#include "pmu/codec/result.hpp"

namespace pmu::codec {

struct CandumpLine {
  bool has_time = false;
  std::int64_t seconds = 0;
  std::uint32_t microseconds = 0;
  std::string_view interface;  // points into the parsed line
  CanFrame frame;
};

struct CandumpError {
  std::string_view reason;  // a static message, e.g. "id must be 3 or 8 hex digits"
};

Result<CandumpLine, CandumpError> parse_candump_line(std::string_view line) noexcept;

}  // namespace pmu::codec
