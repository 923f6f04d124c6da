// candump text parsing (codec/include/pmu/codec/candump.hpp): both of can-utils' text forms,
// every example of the header, and one row per error reason. Expected frames are written out
// by hand from the text of each line.
#include "pmu/codec/candump.hpp"

#include <gtest/gtest.h>

#include <array>
#include <cstdint>
#include <string>
#include <string_view>

namespace pmu::codec {
namespace {

struct Good {
  std::string_view line;
  bool has_time;
  std::int64_t seconds;
  std::uint32_t microseconds;
  std::string_view interface;
  std::uint32_t id;
  bool extended;
  bool remote;
  std::uint8_t length;
  std::array<std::uint8_t, kMaxDataLength> data;  // bytes past `length` must stay 0
};

constexpr bool kExt = true, kStd = false;
constexpr bool kRtr = true, kData = false;
constexpr bool kTime = true, kNoTime = false;

void expect_good(const Good& g) {
  SCOPED_TRACE(std::string("line: \"") + std::string(g.line) + "\"");
  const auto r = parse_candump_line(g.line);
  ASSERT_TRUE(r.ok()) << r.error().reason;
  const CandumpLine& c = r.value();
  EXPECT_EQ(c.has_time, g.has_time);
  EXPECT_EQ(c.seconds, g.seconds);
  EXPECT_EQ(c.microseconds, g.microseconds);
  EXPECT_EQ(c.interface, g.interface);
  // The interface is a view into the line, not a copy.
  EXPECT_GE(c.interface.data(), g.line.data());
  EXPECT_LE(c.interface.data() + c.interface.size(), g.line.data() + g.line.size());
  EXPECT_EQ(c.frame.id, g.id);
  EXPECT_EQ(c.frame.extended, g.extended);
  EXPECT_EQ(c.frame.remote, g.remote);
  EXPECT_EQ(c.frame.length, g.length);
  for (std::size_t i = 0; i < kMaxDataLength; ++i) EXPECT_EQ(c.frame.data[i], g.data[i]) << "byte " << i;
}

template <std::size_t N>
void expect_all_good(const Good (&rows)[N]) {
  for (const Good& g : rows) expect_good(g);
}

struct Bad {
  std::string_view line;
  std::string_view reason;
};

template <std::size_t N>
void expect_all_bad(const Bad (&rows)[N]) {
  for (const Bad& b : rows) {
    SCOPED_TRACE(std::string("line: \"") + std::string(b.line) + "\"");
    const auto r = parse_candump_line(b.line);
    ASSERT_FALSE(r.ok()) << "parsed a frame with id " << r->frame.id;
    EXPECT_EQ(r.error().reason, b.reason);
  }
}

// ---- the header's examples ---------------------------------------------------------------------
TEST(Candump, HeaderExamplesLogForm) {
  const Good rows[] = {
      {"(1700000000.000000) can0 1E000001#FA0A", kTime, 1700000000, 0, "can0", 0x1E000001, kExt, kData, 2, {0xFA, 0x0A}},
      {"(1700000000.000000) can0 202#0102030405060708",
       kTime,
       1700000000,
       0,
       "can0",
       0x202,
       kStd,
       kData,
       8,
       {0x01, 0x02, 0x03, 0x04, 0x05, 0x06, 0x07, 0x08}},
      {"(1700000000.000000) can0 1E240001#", kTime, 1700000000, 0, "can0", 0x1E240001, kExt, kData, 0, {}},
      {"(1700000000.000000) can0 123#R", kTime, 1700000000, 0, "can0", 0x123, kStd, kRtr, 0, {}},
  };
  expect_all_good(rows);
}

TEST(Candump, HeaderExamplesScreenForm) {
  const Good rows[] = {
      {"  can0  1E000001   [2]  FA 0A", kNoTime, 0, 0, "can0", 0x1E000001, kExt, kData, 2, {0xFA, 0x0A}},
      {" (1700000000.000000)  can0  202   [8]  01 02 03 04 05 06 07 08",
       kTime,
       1700000000,
       0,
       "can0",
       0x202,
       kStd,
       kData,
       8,
       {0x01, 0x02, 0x03, 0x04, 0x05, 0x06, 0x07, 0x08}},
      {"  can0  123   [0]  remote request", kNoTime, 0, 0, "can0", 0x123, kStd, kRtr, 0, {}},
  };
  expect_all_good(rows);
}

// ---- identifiers: 3 hex digits standard, 8 extended (can-utils lib.h) ----------------------------
TEST(Candump, StandardAndExtendedIds) {
  const Good rows[] = {
      {"can0 000#", kNoTime, 0, 0, "can0", 0x000, kStd, kData, 0, {}},
      {"can0 7FF#", kNoTime, 0, 0, "can0", 0x7FF, kStd, kData, 0, {}},
      {"vcan1 202#64", kNoTime, 0, 0, "vcan1", 0x202, kStd, kData, 1, {0x64}},
      {"can0 00000000#", kNoTime, 0, 0, "can0", 0x00000000, kExt, kData, 0, {}},
      // 8 digits make an extended id even when the value would fit 11 bits.
      {"can0 00000123#11", kNoTime, 0, 0, "can0", 0x123, kExt, kData, 1, {0x11}},
      {"can0 1FFFFFFF#FF", kNoTime, 0, 0, "can0", 0x1FFFFFFF, kExt, kData, 1, {0xFF}},
      {"can0 1e00000a#fa0b", kNoTime, 0, 0, "can0", 0x1E00000A, kExt, kData, 2, {0xFA, 0x0B}},  // lower case
      {"  can0  7FF   [1]  aa", kNoTime, 0, 0, "can0", 0x7FF, kStd, kData, 1, {0xAA}},
      {"  can0  1FFFFFFF   [0]", kNoTime, 0, 0, "can0", 0x1FFFFFFF, kExt, kData, 0, {}},
  };
  expect_all_good(rows);
}

// ---- 0..8 data bytes, both forms, with and without a timestamp ---------------------------------
TEST(Candump, EveryLengthZeroToEight) {
  const char* const hex[] = {"00", "11", "22", "33", "44", "55", "66", "77"};
  for (std::uint8_t n = 0; n <= kMaxDataLength; ++n) {
    std::string log_data, screen_data;
    std::array<std::uint8_t, kMaxDataLength> data{};
    for (std::uint8_t i = 0; i < n; ++i) {
      log_data += hex[i];
      screen_data += std::string(" ") + hex[i];
      data[i] = static_cast<std::uint8_t>(0x11 * i);
    }
    const std::string lines[] = {
        "can0 1E000001#" + log_data,
        "(1700000001.000002) can0 1E000001#" + log_data,
        "  can0  1E000001   [" + std::to_string(n) + "] " + screen_data,
        " (1700000001.000002)  can0  1E000001   [" + std::to_string(n) + "] " + screen_data,
    };
    for (std::size_t k = 0; k < 4; ++k) {
      const bool timed = k % 2 == 1;
      expect_good({lines[k], timed, timed ? 1700000001 : 0, timed ? 2u : 0u, "can0", 0x1E000001, kExt, kData, n, data});
    }
  }
}

TEST(Candump, CansendDotsBetweenBytes) {
  // cansend's syntax (can-utils lib.h): "5AA#11.2233.44556677.88" - dots may separate bytes.
  const Good rows[] = {
      {"can0 123#01.02.03", kNoTime, 0, 0, "can0", 0x123, kStd, kData, 3, {0x01, 0x02, 0x03}},
      {"can0 5AA#11.2233.44556677.88",
       kNoTime,
       0,
       0,
       "can0",
       0x5AA,
       kStd,
       kData,
       8,
       {0x11, 0x22, 0x33, 0x44, 0x55, 0x66, 0x77, 0x88}},
  };
  expect_all_good(rows);
}

// ---- remote frames ---------------------------------------------------------------------------------
TEST(Candump, RemoteFrames) {
  const Good rows[] = {
      {"can0 123#R", kNoTime, 0, 0, "can0", 0x123, kStd, kRtr, 0, {}},
      {"can0 123#r", kNoTime, 0, 0, "can0", 0x123, kStd, kRtr, 0, {}},
      // can-utils writes a non-zero DLC of a remote frame after the R.
      {"can0 123#R3", kNoTime, 0, 0, "can0", 0x123, kStd, kRtr, 3, {}},
      {"can0 123#R8", kNoTime, 0, 0, "can0", 0x123, kStd, kRtr, 8, {}},
      {"(1700000000.000000) can0 1E000001#R", kTime, 1700000000, 0, "can0", 0x1E000001, kExt, kRtr, 0, {}},
      {"  can0  123   [3]  remote request", kNoTime, 0, 0, "can0", 0x123, kStd, kRtr, 3, {}},
      {"  can0  1E000001   [8]  remote request", kNoTime, 0, 0, "can0", 0x1E000001, kExt, kRtr, 8, {}},
  };
  expect_all_good(rows);
}

// ---- candump -x direction flag, candump -a ASCII, line endings ------------------------------------
TEST(Candump, TrailingDirectionFlag) {
  const Good rows[] = {
      {"(1700000000.000000) can0 1E000001#FA0A T",
       kTime,
       1700000000,
       0,
       "can0",
       0x1E000001,
       kExt,
       kData,
       2,
       {0xFA, 0x0A}},
      {"(1700000000.000000) can0 1E000001#FA0A R",
       kTime,
       1700000000,
       0,
       "can0",
       0x1E000001,
       kExt,
       kData,
       2,
       {0xFA, 0x0A}},
      {"can0 123#R R", kNoTime, 0, 0, "can0", 0x123, kStd, kRtr, 0, {}},
      {"can0 123# T\r\n", kNoTime, 0, 0, "can0", 0x123, kStd, kData, 0, {}},
  };
  expect_all_good(rows);
}

TEST(Candump, AsciiSuffix) {
  const Good rows[] = {
      {"  can0  123   [4]  31 32 33 34   '1234'", kNoTime, 0, 0, "can0", 0x123, kStd, kData, 4, {0x31, 0x32, 0x33, 0x34}},
      {"  can0  1E000001   [2]  FA 0A   '..'", kNoTime, 0, 0, "can0", 0x1E000001, kExt, kData, 2, {0xFA, 0x0A}},
      {" (1700000000.000000)  can0  202   [1]  41   'A'", kTime, 1700000000, 0, "can0", 0x202, kStd, kData, 1, {0x41}},
      {"  can0  123   [0]   ''", kNoTime, 0, 0, "can0", 0x123, kStd, kData, 0, {}},
  };
  expect_all_good(rows);
}

TEST(Candump, LineEndingsAndWhitespace) {
  const Good rows[] = {
      {"(1700000000.000000) can0 1E000001#FA0A\r\n",
       kTime,
       1700000000,
       0,
       "can0",
       0x1E000001,
       kExt,
       kData,
       2,
       {0xFA, 0x0A}},
      {"(1700000000.000000) can0 1E000001#FA0A\n",
       kTime,
       1700000000,
       0,
       "can0",
       0x1E000001,
       kExt,
       kData,
       2,
       {0xFA, 0x0A}},
      {"  can0  1E000001   [2]  FA 0A\r\n", kNoTime, 0, 0, "can0", 0x1E000001, kExt, kData, 2, {0xFA, 0x0A}},
      {"\tcan0\t1E000001\t[2]\tFA\t0A\t", kNoTime, 0, 0, "can0", 0x1E000001, kExt, kData, 2, {0xFA, 0x0A}},
      {"   (1700000000.000000)    can0    123#11   \n", kTime, 1700000000, 0, "can0", 0x123, kStd, kData, 1, {0x11}},
      {"  can0  123   [0]  remote request\r\n", kNoTime, 0, 0, "can0", 0x123, kStd, kRtr, 0, {}},
  };
  expect_all_good(rows);
}

// ---- timestamps ---------------------------------------------------------------------------------
// candump writes six fractional digits; fewer are scaled ("(1.5)" is 1 s 500000 us).
TEST(Candump, Timestamps) {
  const Good rows[] = {
      {"(1700000000.5) can0 123#", kTime, 1700000000, 500000, "can0", 0x123, kStd, kData, 0, {}},
      {"(1700000000.25) can0 123#", kTime, 1700000000, 250000, "can0", 0x123, kStd, kData, 0, {}},
      {"(1700000000.123) can0 123#", kTime, 1700000000, 123000, "can0", 0x123, kStd, kData, 0, {}},
      {"(1700000000.00001) can0 123#", kTime, 1700000000, 10, "can0", 0x123, kStd, kData, 0, {}},
      {"(1700000000.999999) can0 123#", kTime, 1700000000, 999999, "can0", 0x123, kStd, kData, 0, {}},
      {"(0.000001) can0 123#", kTime, 0, 1, "can0", 0x123, kStd, kData, 0, {}},
      {"(0000000042.000000) can0 123#", kTime, 42, 0, "can0", 0x123, kStd, kData, 0, {}},
      // More than six digits: cut to microseconds, not rounded.
      {"(1700000000.1234567) can0 123#", kTime, 1700000000, 123456, "can0", 0x123, kStd, kData, 0, {}},
      {" (1700000000.5)  can0  123   [1]  AA", kTime, 1700000000, 500000, "can0", 0x123, kStd, kData, 1, {0xAA}},
  };
  expect_all_good(rows);
}

// ---- errors, one table per reason -----------------------------------------------------------------
TEST(CandumpErrors, EmptyLine) {
  const Bad rows[] = {{"", "empty line"}, {"   ", "empty line"}, {"\r\n", "empty line"}, {"\t \r\n", "empty line"}};
  expect_all_bad(rows);
}

TEST(CandumpErrors, BadHex) {
  const Bad rows[] = {
      {"can0 123#0G", "data is not hex"},
      {"can0 123#G0", "data is not hex"},
      {"can0 123#0x01", "data is not hex"},
      {"  can0  123   [1]  0G", "data byte is not two hex digits"},
      {"  can0  123   [2]  0A1 02", "data byte is not two hex digits"},
      {"  can0  123   [1]  A", "data byte is not two hex digits"},
  };
  expect_all_bad(rows);
}

TEST(CandumpErrors, OddNumberOfDigits) {
  const Bad rows[] = {
      {"can0 123#A", "odd number of hex digits in data"},
      {"can0 123#ABC", "odd number of hex digits in data"},
      {"(1700000000.000000) can0 1E000001#FA0A0", "odd number of hex digits in data"},
  };
  expect_all_bad(rows);
}

TEST(CandumpErrors, NineBytes) {
  const Bad rows[] = {
      {"can0 123#000102030405060708", "more than 8 data bytes"},
      {"  can0  123   [9]  00 01 02 03 04 05 06 07 08", "length above 8: CAN FD frames are not supported"},
  };
  expect_all_bad(rows);
}

TEST(CandumpErrors, LengthMismatch) {
  const Bad rows[] = {
      {"  can0  123   [3]  01 02", "fewer data bytes than [length]"},
      {"  can0  123   [8]", "fewer data bytes than [length]"},
      {"  can0  123   [1]  01 02", "more data bytes than [length]"},
      {"  can0  123   [0]  01", "more data bytes than [length]"},
  };
  expect_all_bad(rows);
}

TEST(CandumpErrors, CanFd) {
  const Bad rows[] = {
      {"can0 123##1000102", "CAN FD frame: the PMU uses classic CAN"},
      {"(1700000000.000000) can0 1E000001##0FA0A", "CAN FD frame: the PMU uses classic CAN"},
      {"  can0  123  [12]  00 01 02 03 04 05 06 07 08 09 0A 0B", "length above 8: CAN FD frames are not supported"},
      {"  can0  123  [64]  00", "length above 8: CAN FD frames are not supported"},
  };
  expect_all_bad(rows);
}

TEST(CandumpErrors, WrongIdWidthOrValue) {
  constexpr std::string_view kId = "id must be 3 (standard) or 8 (extended) hex digits";
  const Bad rows[] = {
      {"can0 12#00", kId},
      {"can0 1234#00", kId},
      {"can0 1E00001#00", kId},    // 7 digits
      {"can0 1E0000011#00", kId},  // 9 digits
      {"can0 #00", kId},
      {"can0 12G#00", kId},
      {"  can0  12   [0]", kId},
      {"  can0  1234   [0]", kId},
      // over 11 bits in 3 digits, over 29 bits in 8
      {"can0 800#00", kId},
      {"can0 FFF#", kId},
      {"can0 20000000#00", kId},
      {"can0 FFFFFFFF#", kId},
      {"  can0  20000000   [0]", kId},
  };
  expect_all_bad(rows);
}

TEST(CandumpErrors, MissingInterfaceOrFrame) {
  const Bad rows[] = {
      {"(1700000000.000000)", "missing interface"},  {"(1700000000.000000) 1E000001#FA0A", "missing interface"},
      {"1E000001#FA0A", "missing interface"},        {"can0", "missing frame"},
      {"(1700000000.000000) can0", "missing frame"}, {"(1700000000.000000) can0 \r\n", "missing frame"},
  };
  expect_all_bad(rows);
}

TEST(CandumpErrors, BadTimestamp) {
  constexpr std::string_view kTs = "bad timestamp: expected (seconds.microseconds)";
  const Bad rows[] = {
      {"(1700000000) can0 123#", kTs}, {"(1700000000.) can0 123#", kTs}, {"(.5) can0 123#", kTs},
      {"(17x0.5) can0 123#", kTs},     {"(1.5x) can0 123#", kTs},        {"(1.5 can0 123#", kTs},
      {"() can0 123#", kTs},           {"(-1.5) can0 123#", kTs},
  };
  expect_all_bad(rows);
}

TEST(CandumpErrors, BadLengthField) {
  const Bad rows[] = {
      {"  can0  123", "missing [length]"},           {"  can0  123  01 02", "missing [length]"},
      {"  can0  123  [2 01 02", "missing [length]"}, {"  can0  123  []", "missing [length]"},
      {"  can0  123  [x]  01", "bad [length]"},      {"  can0  123  [-1]", "bad [length]"},
  };
  expect_all_bad(rows);
}

TEST(CandumpErrors, BadRemoteLength) {
  const Bad rows[] = {
      {"can0 123#R9", "bad remote frame length"},
      {"can0 123#RR", "bad remote frame length"},
      {"can0 123#R12", "bad remote frame length"},
  };
  expect_all_bad(rows);
}

TEST(CandumpErrors, TextAfterTheFrame) {
  const Bad rows[] = {
      {"can0 123#00 X", "unexpected text after the frame"},
      {"can0 123#00 T T", "unexpected text after the frame"},
      {"can0 123#00 TX", "unexpected text after the frame"},
      {"can0 1E000001#FA0A can1 123#00", "unexpected text after the frame"},
  };
  expect_all_bad(rows);
}

TEST(CandumpErrors, Garbage) {
  constexpr std::string_view kId = "id must be 3 (standard) or 8 (extended) hex digits";
  const Bad rows[] = {
      {"garbage", "missing frame"},
      {"hello world", kId},
      {"!!!! ????", kId},
      {"\x01\x02\x03 \xff", kId},
      {std::string_view("can0 12\0#00", 11), kId},  // an embedded NUL is not a hex digit
  };
  expect_all_bad(rows);
}

}  // namespace
}  // namespace pmu::codec
