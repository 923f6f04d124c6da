#include "telemetry/wire_units.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>

namespace pmu::mavlink_bridge {
namespace {

constexpr float kNaN = std::numeric_limits<float>::quiet_NaN();
constexpr float kInf = std::numeric_limits<float>::infinity();

struct Case {
  const char* name;
  float in;
  std::int32_t out;
};

TEST(WireUnits, Millivolts) {
  const Case cases[] = {{"nan is not provided", kNaN, 65535}, {"inf is not provided", kInf, 65535},
                        {"zero volts is 0 mV", 0.0F, 0},      {"24.05 V", 24.05F, 24050},
                        {"negative clamps to 0", -1.0F, 0},   {"too high stays below the sentinel", 70.0F, 65534}};
  for (const auto& c : cases) EXPECT_EQ(millivolts(c.in), c.out) << c.name;
}

TEST(WireUnits, MillivoltsExt) {
  const Case cases[] = {{"nan is 0 (the ext field's not provided)", kNaN, 0},
                        {"a measured 0 is sent as 1", 0.0F, 1},
                        {"3.7 V", 3.7F, 3700}};
  for (const auto& c : cases) EXPECT_EQ(millivolts_ext(c.in), c.out) << c.name;
}

TEST(WireUnits, Temperatures) {
  EXPECT_EQ(centidegrees(kNaN), std::numeric_limits<std::int16_t>::max());
  EXPECT_EQ(centidegrees(0.0F), 0);
  EXPECT_EQ(centidegrees(-12.5F), -1250);
  EXPECT_EQ(centidegrees(400.0F), 32766) << "a known value never reads as the sentinel";
  EXPECT_EQ(whole_degrees(kNaN), std::numeric_limits<std::int16_t>::max());
  EXPECT_EQ(whole_degrees(61.6F), 62);
}

TEST(WireUnits, Centiamperes) {
  const Case cases[] = {{"nan is -1", kNaN, -1},
                        {"a measured -0.01 A is not the sentinel", -0.01F, 0},
                        {"0 A is 0", 0.0F, 0},
                        {"12.34 A", 12.34F, 1234},
                        {"-5 A (charging)", -5.0F, -500},
                        {"overflow clamps", 400.0F, 32767}};
  for (const auto& c : cases) EXPECT_EQ(centiamperes(c.in), c.out) << c.name;
}

}  // namespace
}  // namespace pmu::mavlink_bridge
