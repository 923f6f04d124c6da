#pragma once
// Values from outside (a config file, the command line) shown inside an error message: a
// value may be a megabyte, or carry bytes that are half of a UTF-8 character at the cut.

#include <cstddef>
#include <string>
#include <string_view>

namespace pmu::dds {

// 'value' in quotes; past 32 bytes the first 24 (never cut inside a UTF-8 sequence) and
// "...' (N bytes)", so a message stays one readable line. Control bytes and bytes that start
// no valid UTF-8 sequence are written \xNN.
std::string quoted(std::string_view value);

// The character that starts at byte `at` of `s`, for "contains X": 'é' for a whole UTF-8
// sequence or printable ASCII, "byte 0xFF" for a control byte or one that starts no valid
// sequence.
std::string character_at(std::string_view s, std::size_t at);

}  // namespace pmu::dds
