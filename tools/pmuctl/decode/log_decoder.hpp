#pragma once
// `pmuctl decode`: one candump line in, exactly one output line out (a decoded frame, or
// {"line": N, "error": "..."}), so a log and its decoding line up and a bad line never
// stops the rest. I/O stays in main; this class turns text into text.

#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <unordered_map>

#include "pmu/codec/firmware.hpp"

namespace pmu::tools {

struct DecodeOptions {
  bool json = false;
  // Firmware assumed for devices whose firmware reply (0x31) has not been seen in the log.
  std::optional<codec::FirmwareVersion> firmware;
};

struct DecodeCounts {
  std::uint64_t lines = 0;
  std::uint64_t frames = 0;  // lines decoded to a PMU or CANopen frame
  std::uint64_t errors = 0;  // lines reported as errors
  // Lines timed before kEarliestAbsoluteTime: candump -td (deltas) or -tz (since its start)
  // rather than -ta or -L, so their times are not dates. Printed as given; main says so.
  std::uint64_t relative_times = 0;
};

// 1973-03-03 (10^8 s after 1970): no CAN log of this device is older, and candump's relative
// times (-td, -tz) stay below it for three years of recording.
inline constexpr std::int64_t kEarliestAbsoluteTime = 100000000;

class LogDecoder {
 public:
  explicit LogDecoder(DecodeOptions options);

  // Decodes one input line (without its newline) and appends one output line, with '\n'.
  void decode_line(std::string_view line, std::string& out);

  // The header line of the table form ("" for JSON).
  std::string header() const;
  const DecodeCounts& counts() const { return counts_; }

 private:
  std::optional<codec::FirmwareVersion> firmware_of(std::uint16_t address) const;

  DecodeOptions options_;
  DecodeCounts counts_;
  // Firmware learned from 0x31 replies in the log, per device address.
  std::unordered_map<std::uint16_t, codec::FirmwareVersion> learned_;
};

}  // namespace pmu::tools
