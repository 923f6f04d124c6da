// pmuctl's --timeout and --count: every text is a value or a reason that names the option.
#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include "pmuctl/call/option_values.hpp"

namespace {

using pmu::tools::parse_count;
using pmu::tools::parse_seconds;

struct SecondsCase {
  const char* text;
  double value;  // NAN: refused
};

const SecondsCase kSeconds[] = {
    {"3", 3.0},   {"0.25", 0.25}, {"1e3", 1000.0}, {"604800", 604800.0}, {"nan", NAN},  {"-nan", NAN},
    {"inf", NAN}, {"-inf", NAN},  {"0", NAN},      {"-1", NAN},          {"1e10", NAN}, {"604800.5", NAN},
    {"", NAN},    {"3s", NAN},    {" 3", NAN},     {"1e999", NAN},
};

TEST(OptionValues, SecondsAreFinitePositiveAndAtMostAWeek) {
  for (const auto& c : kSeconds) {
    SCOPED_TRACE(c.text);
    const auto r = parse_seconds("--timeout", c.text);
    if (std::isnan(c.value)) {
      ASSERT_TRUE(std::holds_alternative<std::string>(r));
      const auto& why = std::get<std::string>(r);
      EXPECT_EQ(why.rfind("--timeout '" + std::string(c.text) + "'", 0), 0u) << why;
      EXPECT_NE(why.find("at most 604800"), std::string::npos) << why;
    } else {
      ASSERT_TRUE(std::holds_alternative<double>(r)) << std::get<std::string>(r);
      EXPECT_DOUBLE_EQ(std::get<double>(r), c.value);
    }
  }
}

struct CountCase {
  const char* text;
  long value;  // 0: refused
};

const CountCase kCounts[] = {
    {"1", 1},   {"20", 20}, {"1000000000", 1000000000},
    {"0", 0},   {"-1", 0},  {"1000000001", 0},
    {"1.5", 0}, {"", 0},    {"+3", 0},
    {" 3", 0},  {"x", 0},   {"99999999999999999999", 0},
};

TEST(OptionValues, CountsAreWholeNumbersFromOne) {
  for (const auto& c : kCounts) {
    SCOPED_TRACE(c.text);
    const auto r = parse_count("--count", c.text);
    if (c.value == 0) {
      ASSERT_TRUE(std::holds_alternative<std::string>(r));
      const auto& why = std::get<std::string>(r);
      EXPECT_EQ(why, "--count '" + std::string(c.text) + "' is not a whole number 1..1000000000");
      // The range is said in digits a person reads, never DBL_MAX's 309.
      EXPECT_LT(why.size(), 80u);
    } else {
      ASSERT_TRUE(std::holds_alternative<long>(r)) << std::get<std::string>(r);
      EXPECT_EQ(std::get<long>(r), c.value);
    }
  }
}

TEST(OptionValues, ALongValueIsEchoedShort) {
  const std::string huge(1 << 20, '9');
  const auto r = parse_seconds("--timeout", huge);
  ASSERT_TRUE(std::holds_alternative<std::string>(r));
  EXPECT_LT(std::get<std::string>(r).size(), 160u);
  EXPECT_NE(std::get<std::string>(r).find("..."), std::string::npos);
}

}  // namespace
