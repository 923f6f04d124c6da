// pmu/baseline's sample (interface.md 1.9) and back, without a participant: what the service
// writes from a configured file reads back as the same settings and pins, for every
// parameter's range, and a device's pmu/config compares with it on the wire's values.
#include <gtest/gtest.h>

#include "pmu/baseline/config_diff.hpp"
#include "pmu/dds/baseline_sample.hpp"

namespace pmu::service::baseline_sample_test {
namespace {

using baseline::Setting;

// What the service's config holds of a PMU with a `baseline:`.
struct DeviceConfig {
  std::uint16_t address = 1;
  std::string baseline_file;
  std::optional<baseline::ConfigFile> baseline;
};

DeviceConfig configured(const std::string& text) {
  DeviceConfig d;
  d.address = 3;
  d.baseline_file = "pmu3.yaml";
  auto f = baseline::read_config_file(text);
  EXPECT_TRUE(f.ok()) << (f.ok() ? "" : f.error().message);
  if (f.ok()) d.baseline = *f;
  return d;
}

// The sample of a configured device, as the service's publisher writes it.
pmu::v5::Baseline baseline_sample(const std::string& vehicle, const std::string& bus, const DeviceConfig& d) {
  return service::baseline_sample(vehicle, bus, d.address, d.baseline_file, d.baseline);
}

TEST(BaselineSample, KeysPinsAndOnlyTheSettingsTheFileHas) {
  const auto s = baseline_sample("uav1", "can0",
                                 configured("device:\n  serial: 1001\n  min_firmware: \"1.14\"\n"
                                            "parameters:\n  servo_voltage: 7.5\noutputs: [payload]\n"));
  EXPECT_EQ(s.vehicle(), "uav1");
  EXPECT_EQ(s.bus(), "can0");
  EXPECT_EQ(s.address(), 3);
  EXPECT_EQ(s.file(), "pmu3.yaml");
  EXPECT_TRUE(s.has_serial());
  EXPECT_EQ(s.serial(), 1001);
  EXPECT_TRUE(s.has_min_firmware());
  EXPECT_EQ(s.min_firmware_major(), 1);
  EXPECT_EQ(s.min_firmware_minor(), 14);
  EXPECT_EQ(s.present(), (1u << 2) | (1u << 11));
  EXPECT_FLOAT_EQ(s.servo_voltage(), 7.5f);
  EXPECT_EQ(s.outputs(), 0x02);
  EXPECT_FLOAT_EQ(s.avionics_voltage(), 0.0f) << "not in the file";

  const auto none = baseline_sample("", "can0", configured("parameters:\n  can_address: 3\n"));
  EXPECT_FALSE(none.has_serial());
  EXPECT_FALSE(none.has_min_firmware());
  EXPECT_EQ(none.present(), 1u << 10);
}

// Each parameter at the ends of its range and in the middle, through the IDL's floats and
// octets and back: the same raw values, so a diff against the topic is a diff against the file.
TEST(BaselineSample, EveryParameterReadsBackAsTheSameRawValue) {
  for (const auto& spec : codec::parameter_table()) {
    for (const std::uint32_t raw : {spec.raw_min, (spec.raw_min + spec.raw_max) / 2, spec.raw_max}) {
      SCOPED_TRACE(std::string(spec.name) + " " + std::to_string(raw));
      DeviceConfig d;
      d.baseline_file = "f.yaml";
      d.baseline = baseline::ConfigFile{};
      d.baseline->settings[baseline::setting_of(spec.parameter)] = raw;
      d.baseline->settings[Setting::Outputs] = 0x0F;
      d.baseline->settings[Setting::GenerationEnabled] = 0;
      const auto back = config_file_of(baseline_sample("", "can0", d));
      EXPECT_EQ(back.settings.raw, d.baseline->settings.raw);
    }
  }
}

TEST(BaselineSample, AConfigSampleComparesOnTheWiresValues) {
  pmu::v5::Config c;
  c.avionics_voltage(24.0f);
  c.payload_voltage(12.3f);
  c.servo_voltage(6.0f);
  c.battery_voltage(25.2f);
  c.packet_period(0.5f);
  c.packets_streamed(0x1F);
  c.temperature_offset(128);
  c.upper_temperature_limit(80);
  c.power_up_state(0x0F);
  c.cranking_time(5.0f);
  c.can_address(3);
  c.outputs(0x03);
  c.generation_enabled(true);
  const auto device = settings_of(c);
  EXPECT_EQ(device[Setting::AvionicsVoltage], 240u);
  EXPECT_EQ(device[Setting::PayloadVoltage], 123u) << "12.3 as a float is still step 123";
  EXPECT_EQ(device[Setting::PacketPeriod], 5u);
  EXPECT_EQ(device[Setting::GenerationEnabled], 1u);

  const auto file = config_file_of(baseline_sample(
      "", "can0",
      configured(
          "parameters:\n  avionics_voltage: 22.0\n  payload_voltage: 12.3\noutputs: [avionics_servo, payload]\n")));
  const auto diffs = baseline::differences(device, file);
  ASSERT_EQ(diffs.size(), 1u);
  EXPECT_EQ(diffs[0].setting, Setting::AvionicsVoltage);
  EXPECT_EQ(diffs[0].device, 240u);
  EXPECT_EQ(diffs[0].file, 220u);
}

}  // namespace
}  // namespace pmu::service::baseline_sample_test
