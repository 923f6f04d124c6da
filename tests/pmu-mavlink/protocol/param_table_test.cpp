// The parameter table: names a ground station can carry, and REAL32 values that come back
// as the wire value they went out as, for every setting over its whole range.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <set>

#include "pmu/codec/messages.hpp"
#include "pmu/codec/parameters.hpp"
#include "pmu/mavlink_params/param_table.hpp"

namespace pmu::mavlink_params {
namespace {

// Every value a setting's set may carry, as the spec's table gives the range.
struct Range {
  std::uint32_t min, max;
};
Range range_of(Setting s) {
  if (const auto p = baseline::parameter_of(s)) return {codec::spec_of(*p).raw_min, codec::spec_of(*p).raw_max};
  return s == Setting::Outputs ? Range{0, codec::output_bit::All} : Range{0, 1};
}

TEST(ParamTable, EveryNameFitsAndIsUniqueForNinePmus) {
  std::set<std::string> names;
  for (std::size_t pmu = 0; pmu < kMaxPmus; ++pmu) {
    for (const auto& row : param_table()) {
      const auto name = param_name({pmu, row.setting});
      SCOPED_TRACE(name);
      EXPECT_LE(name.size(), kMaxNameLength);
      EXPECT_TRUE(names.insert(name).second) << "duplicate";
      const auto back = param_from_name(name, kMaxPmus);
      ASSERT_TRUE(back);
      EXPECT_EQ(back->pmu, pmu);
      EXPECT_EQ(back->setting, row.setting);
      const auto by_index = param_from_index(param_index({pmu, row.setting}), kMaxPmus);
      ASSERT_TRUE(by_index);
      EXPECT_EQ(*by_index, (ParamRef{pmu, row.setting}));
    }
  }
  EXPECT_EQ(names.size(), kMaxPmus * kSettingCount);
}

TEST(ParamTable, NamesOutsideTheTableAreNone) {
  for (const char* name : {"", "PMU", "PMU1_", "PMU0_AVION_V", "PMU3_AVION_V", "PMU1_AVION_VX", "PMU1AVION_V",
                           "pmu1_AVION_V", "PMU1_avion_v", "PMU11_AVION_V", "BATT_CAPACITY"}) {
    SCOPED_TRACE(name);
    EXPECT_FALSE(param_from_name(name, 2));
  }
  EXPECT_FALSE(param_from_index(-1, 2));
  EXPECT_FALSE(param_from_index(2 * kSettingCount, 2));
  EXPECT_TRUE(param_from_index(2 * kSettingCount - 1, 2));
}

TEST(ParamTable, Real32RoundTripsEveryWireValueOfEverySetting) {
  for (const auto& row : param_table()) {
    const auto r = range_of(row.setting);
    for (std::uint32_t raw = r.min; raw <= r.max; ++raw) {
      const float value = to_real32(row.setting, raw);
      const auto back = from_real32(row.setting, value);
      ASSERT_TRUE(back) << row.suffix << " raw " << raw << ": " << back.error();
      EXPECT_EQ(*back, raw) << row.suffix;
    }
  }
}

TEST(ParamTable, Real32ValuesAreInTheUnitsOfConfigGet) {
  struct Case {
    Setting setting;
    std::uint32_t raw;
    float value;
  };
  for (const auto& c : {Case{Setting::AvionicsVoltage, 240, 24.0F}, Case{Setting::PacketPeriod, 15, 1.5F},
                        Case{Setting::UpperTemperatureLimit, 60, 60.0F}, Case{Setting::PacketsStreamed, 0x13, 19.0F},
                        Case{Setting::CanAddress, 65534, 65534.0F}, Case{Setting::GenerationEnabled, 1, 1.0F}}) {
    EXPECT_EQ(to_real32(c.setting, c.raw), c.value) << spec_of(c.setting).suffix;
  }
}

TEST(ParamTable, ValuesOutOfRangeOffStepOrNotANumberAreRefused) {
  struct Case {
    Setting setting;
    float value;
  };
  for (const auto& c :
       {Case{Setting::AvionicsVoltage, 30.0F}, Case{Setting::AvionicsVoltage, 11.9F},
        Case{Setting::AvionicsVoltage, 23.05F}, Case{Setting::AvionicsVoltage, std::numeric_limits<float>::quiet_NaN()},
        Case{Setting::PacketPeriod, 0.0F}, Case{Setting::PacketsStreamed, 0x20}, Case{Setting::PacketsStreamed, 1.5F},
        Case{Setting::Outputs, 16.0F}, Case{Setting::Outputs, -1.0F}, Case{Setting::GenerationEnabled, 2.0F},
        Case{Setting::GenerationEnabled, 0.5F}, Case{Setting::CanAddress, 65535.0F},
        Case{Setting::UpperTemperatureLimit, std::numeric_limits<float>::infinity()}}) {
    const auto r = from_real32(c.setting, c.value);
    EXPECT_FALSE(r) << spec_of(c.setting).suffix << " " << c.value;
    if (!r) {
      EXPECT_FALSE(r.error().empty());
    }
  }
}

TEST(ParamTable, OnlyTheCanAddressIsReadOnly) {
  for (const auto& row : param_table()) EXPECT_EQ(row.writable, row.setting != Setting::CanAddress) << row.suffix;
}

}  // namespace
}  // namespace pmu::mavlink_params
