// JsonLine (tools/pmuctl/decode/json_line.hpp) writes the bytes nlohmann's dump wrote before it,
// because `pmuctl decode --json` output is compared by scripts: every kind of value, the
// number formats at their edges, and strings that need escaping or are not valid UTF-8.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <nlohmann/json.hpp>
#include <string>

#include "pmuctl/decode/json_line.hpp"

namespace pmu::tools {
namespace {

using Json = nlohmann::ordered_json;

std::string dumped(const Json& j) { return j.dump(-1, ' ', false, Json::error_handler_t::replace) + "\n"; }

TEST(JsonLine, NumbersAreFormattedAsNlohmannFormatsThem) {
  const double table[] = {0.0,          -0.0,
                          1.0,          -1.0,
                          12.3,         16.8,
                          -4.0,         0.1,
                          1e-5,         1.5e-4,
                          123456.7,     1e15,
                          1e16,         1.7e308,
                          5e-324,       25.2,
                          48.4,         1700000000.000131,
                          1700000000.0, 0.30000000000000004,
                          -273.15,      65535.0,
                          2.5e-7};
  for (const double v : table) {
    std::string out;
    JsonLine(out).number("v", v).end();
    Json j;
    j["v"] = v;
    EXPECT_EQ(out, dumped(j)) << "value " << v;
  }
}

TEST(JsonLine, NonFiniteNumbersAreNull) {
  for (const double v :
       {std::nan(""), std::numeric_limits<double>::infinity(), -std::numeric_limits<double>::infinity()}) {
    std::string out;
    JsonLine(out).number("v", v).end();
    EXPECT_EQ(out, "{\"v\":null}\n");
  }
}

TEST(JsonLine, IntegersBooleansAndNull) {
  std::string out;
  JsonLine(out)
      .integer("a", 0)
      .integer("b", -100)
      .integer("c", std::numeric_limits<std::int64_t>::min())
      .integer("d", std::numeric_limits<std::int64_t>::max())
      .boolean("e", true)
      .boolean("f", false)
      .null("g")
      .end();
  Json j;
  j["a"] = 0;
  j["b"] = -100;
  j["c"] = std::numeric_limits<std::int64_t>::min();
  j["d"] = std::numeric_limits<std::int64_t>::max();
  j["e"] = true;
  j["f"] = false;
  j["g"] = nullptr;
  EXPECT_EQ(out, dumped(j));
}

TEST(JsonLine, StringsAreEscapedAsNlohmannEscapesThem) {
  const std::string table[] = {"",
                               "can0",
                               "id 18FEF100 is not a PMU frame",
                               "quote \" and backslash \\",
                               "tab\tnewline\ncr\r",
                               std::string("nul\0byte", 8),
                               "\x01\x1f\x7f",
                               "caf\xc3\xa9 \xe2\x82\xac",  // valid UTF-8
                               "bad \xff\xfe utf-8",        // replaced by U+FFFD
                               "cut \xe2\x82"};
  for (const std::string& s : table) {
    std::string out;
    JsonLine(out).string("s", s).end();
    Json j;
    j["s"] = s;
    EXPECT_EQ(out, dumped(j)) << "string " << Json(s).dump(-1, ' ', true, Json::error_handler_t::replace);
  }
}

TEST(JsonLine, NestedObjectsAndMemberOrder) {
  std::string out;
  {
    JsonLine j(out);
    j.number("time", 1.5).string("packet", "voltages").begin_object("values");
    j.number("avionics", 12.3).number("payload", std::nan("")).end_object();
    j.begin_object("empty").end_object().boolean("request", true).end();
  }
  Json j;
  j["time"] = 1.5;
  j["packet"] = "voltages";
  j["values"]["avionics"] = 12.3;
  j["values"]["payload"] = nullptr;
  j["empty"] = Json::object();
  j["request"] = true;
  EXPECT_EQ(out, dumped(j));
}

TEST(JsonLine, ALineLongerThanItsBufferIsWhole) {
  std::string out;
  {
    JsonLine j(out);
    for (int i = 0; i < 100; ++i) j.number("value_" + std::to_string(i), i + 0.25);
    j.string("long", std::string(2000, 'x')).end();
  }
  Json j;
  for (int i = 0; i < 100; ++i) j["value_" + std::to_string(i)] = i + 0.25;
  j["long"] = std::string(2000, 'x');
  EXPECT_EQ(out, dumped(j));
}

}  // namespace
}  // namespace pmu::tools
