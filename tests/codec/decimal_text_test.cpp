// The spellings of numbers the files take (codec/decimal_text.hpp, interface.md 4.1 and 4.6):
// plain decimal only, so no number is ever read in another base or by another rule.
#include "pmu/codec/decimal_text.hpp"

#include <gtest/gtest.h>

namespace pmu::codec {
namespace {

struct Row {
  const char* text;
  bool integer;  // is_plain_decimal
  bool number;   // is_plain_decimal_number
};

const Row kRows[] = {
    {"0", true, true},       {"7", true, true},       {"65534", true, true},  {"-3", true, true},
    {"-0", true, true},      {"24.0", false, true},   {"0.5", false, true},   {"-12.25", false, true},
    {"1.5", false, true},    {"", false, false},      {"-", false, false},    {"010", false, false},
    {"00", false, false},    {"0x10", false, false},  {"0x18", false, false}, {"0o10", false, false},
    {"1e1", false, false},   {"2.4e1", false, false}, {"+5", false, false},   {"+24.0", false, false},
    {".5", false, false},    {"5.", false, false},    {"-.5", false, false},  {" 5", false, false},
    {"5 ", false, false},    {"24 V", false, false},  {"inf", false, false},  {"nan", false, false},
    {"1.2.3", false, false}, {"024.0", false, false}, {"1,5", false, false},  {"--1", false, false},
};

TEST(DecimalText, OnlyPlainDecimalIsANumber) {
  for (const auto& r : kRows) {
    EXPECT_EQ(is_plain_decimal(r.text), r.integer) << "'" << r.text << "'";
    EXPECT_EQ(is_plain_decimal_number(r.text), r.number) << "'" << r.text << "'";
  }
}

}  // namespace
}  // namespace pmu::codec
