// A PMU's configuration file (interface.md 4.6): what snapshot writes reads back unchanged
// for every parameter and every firmware the documents describe; every malformed file is
// refused at its line; differences are judged on the wire's values; the apply order and the
// confirm rules.
#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "pmu/baseline/apply_plan.hpp"
#include "pmu/baseline/config_diff.hpp"
#include "pmu/baseline/config_file.hpp"
#include "pmu/codec/encode.hpp"

namespace pmu::baseline {
namespace {

using codec::FirmwareVersion;
using codec::Parameter;

Settings full_settings(std::uint32_t s0 = 0x03) {
  Settings s;
  s[Setting::AvionicsVoltage] = 240;
  s[Setting::PayloadVoltage] = 120;
  s[Setting::ServoVoltage] = 60;
  s[Setting::BatteryVoltage] = 252;
  s[Setting::PacketPeriod] = 5;
  s[Setting::PacketsStreamed] = 0x1F;
  s[Setting::TemperatureOffset] = 128;
  s[Setting::UpperTemperatureLimit] = 85;
  s[Setting::PowerUpState] = s0;
  s[Setting::CrankingTime] = 50;
  s[Setting::CanAddress] = 1;
  s[Setting::Outputs] = 0x03;
  s[Setting::GenerationEnabled] = 1;
  return s;
}

Header header_for(FirmwareVersion fw) {
  Header h;
  h.vehicle = "uav1";
  h.bus = "can0";
  h.address = 1;
  h.serial = 1001;
  h.firmware = fw;
  h.date = "2026-12-03T07:00:00Z";
  return h;
}

// Every raw value at the edges of each parameter's range and one inside, written and read.
TEST(ConfigFile, EveryParameterRoundTripsAtItsLimits) {
  for (const auto& spec : codec::parameter_table()) {
    const std::uint32_t mid = (spec.raw_min + spec.raw_max) / 2;
    for (const std::uint32_t raw : {spec.raw_min, mid, spec.raw_max}) {
      Settings s = full_settings(0x7F);
      s[setting_of(spec.parameter)] = raw;
      if (spec.parameter == Parameter::PowerUpState && raw == mid) s[Setting::PowerUpState] = 0x3F;
      const std::string text = write_config_file(header_for(codec::kCurrentFirmware), s);
      const auto back = read_config_file(text);
      ASSERT_TRUE(back.ok()) << spec.name << " " << raw << ": " << describe(back.error(), "snapshot") << "\n" << text;
      EXPECT_EQ(back->settings.raw, s.raw) << spec.name << " " << raw << "\n" << text;
      EXPECT_TRUE(differences(s, *back).empty()) << spec.name << " " << raw;
    }
  }
}

// The S0 bits each firmware defines (v1.9 6.7, 6.8): a snapshot of each firmware reads back,
// and a file with a newer firmware's bit is refused for an older device at that line.
TEST(ConfigFile, PowerUpStateRoundTripsOnEveryFirmware) {
  for (std::uint8_t minor = 12; minor <= 17; ++minor) {
    const FirmwareVersion fw{1, minor};
    const std::uint32_t s0 = codec::power_up_state_mask(fw);
    const Settings s = full_settings(s0);
    const auto back = read_config_file(write_config_file(header_for(fw), s));
    ASSERT_TRUE(back.ok()) << "1." << int(minor) << ": " << back.error().message;
    EXPECT_EQ(back->settings.raw, s.raw) << "1." << int(minor);
    ASSERT_TRUE(back->header.firmware.has_value());
    EXPECT_EQ(*back->header.firmware, fw);
    EXPECT_FALSE(check_firmware(*back, fw).has_value()) << "1." << int(minor);
  }
  const auto newest = read_config_file(write_config_file(header_for({1, 17}), full_settings(0x7F)));
  ASSERT_TRUE(newest.ok());
  const auto old = check_firmware(*newest, FirmwareVersion{1, 14});
  ASSERT_TRUE(old.has_value());
  EXPECT_EQ(old->line, newest->line_of(Setting::PowerUpState));
  EXPECT_NE(old->message.find("power_up_state"), std::string::npos) << old->message;
}

// A unit can hold what no set writes (packet_period 0 here): its file is refused at that
// value's line, which is how `config snapshot` knows not to write it.
TEST(ConfigFile, AValueNoSetCanWriteDoesNotReadBack) {
  Settings s = full_settings();
  s[Setting::PacketPeriod] = 0;
  const auto back = read_config_file(write_config_file(header_for(codec::kCurrentFirmware), s));
  ASSERT_FALSE(back.ok());
  EXPECT_NE(back.error().message.find("packet_period"), std::string::npos) << back.error().message;
  EXPECT_EQ(back.error().line, 16) << back.error().message;  // packet_period's line in the written file
}

TEST(ConfigFile, TheHeaderReadsBack) {
  Header h = header_for({1, 15});
  h.vehicle = "uav \"7\"";
  h.min_firmware = FirmwareVersion{1, 14};
  const auto back = read_config_file(write_config_file(h, full_settings()));
  ASSERT_TRUE(back.ok()) << back.error().message;
  EXPECT_EQ(back->header.vehicle, h.vehicle);
  EXPECT_EQ(back->header.bus, "can0");
  EXPECT_EQ(back->header.address, std::optional<std::uint16_t>(1));
  EXPECT_EQ(back->header.serial, std::optional<std::uint16_t>(1001));
  EXPECT_EQ(back->header.min_firmware, h.min_firmware);
  EXPECT_EQ(back->header.date, h.date);
  EXPECT_GT(back->serial_line, 0);
  EXPECT_GT(back->min_firmware_line, 0);
}

// What a person writes by hand: names, none, numbers, values between steps.
TEST(ConfigFile, HandWrittenValuesAreTheWireValues) {
  const auto f = read_config_file(
      "parameters:\n"
      "  avionics_voltage: 12.04\n"
      "  payload_voltage: 24\n"
      "  packets_streamed: none\n"
      "  power_up_state: 0x13\n"
      "  cranking_time: 0\n"
      "outputs: []\n"
      "generation_enabled: false\n");
  ASSERT_TRUE(f.ok()) << f.error().message;
  EXPECT_EQ(f->settings[Setting::AvionicsVoltage], std::optional<std::uint32_t>(120));
  EXPECT_EQ(f->settings[Setting::PayloadVoltage], std::optional<std::uint32_t>(240));
  EXPECT_EQ(f->settings[Setting::PacketsStreamed], std::optional<std::uint32_t>(0));
  EXPECT_EQ(f->settings[Setting::PowerUpState], std::optional<std::uint32_t>(0x13));
  EXPECT_EQ(f->settings[Setting::CrankingTime], std::optional<std::uint32_t>(0));
  EXPECT_EQ(f->settings[Setting::Outputs], std::optional<std::uint32_t>(0));
  EXPECT_EQ(f->settings[Setting::GenerationEnabled], std::optional<std::uint32_t>(0));
  EXPECT_EQ(f->line_of(Setting::AvionicsVoltage), 2);
  EXPECT_EQ(f->line_of(Setting::GenerationEnabled), 8);
  EXPECT_FALSE(f->settings[Setting::CanAddress].has_value());
}

struct Malformed {
  const char* what;
  const char* text;
  int line;
  const char* says;
};

// Each is refused whole, at the line of what is wrong, with words that name it.
const Malformed kMalformed[] = {
    {"empty", "", 1, "empty"},
    {"only a comment", "# nothing\n", 1, "empty"},
    {"a list, not a mapping", "- avionics_voltage\n", 1, "must be a mapping"},
    {"unknown top-level key", "parameters:\n  avionics_voltage: 24.0\nbatteries: 2\n", 3, "unknown key 'batteries'"},
    {"unknown parameter", "parameters:\n  avionics_voltage: 24.0\n  avionic_voltage: 24.0\n", 3,
     "unknown parameter 'avionic_voltage'"},
    {"parameter twice", "parameters:\n  avionics_voltage: 24.0\n  avionics_voltage: 22.0\n", 3, "appears twice"},
    {"top-level key twice", "outputs: [payload]\ngeneration_enabled: true\noutputs: []\n", 3, "appears twice"},
    {"out of range high", "parameters:\n  avionics_voltage: 30.0\n", 2, "out of range 12.0..24.0 V"},
    {"out of range low", "parameters:\n\n  servo_voltage: 4.9\n", 3, "out of range"},
    {"a unit after the number", "parameters:\n  payload_voltage: 24 V\n", 2, "is not a number"},
    {"not a number", "parameters:\n  cranking_time: five\n", 2, "is not a number"},
    {"infinite", "parameters:\n  cranking_time: .inf\n", 2, "is not a number"},
    {"NaN", "parameters:\n  battery_voltage: .nan\n", 2, "is not a number"},
    {"a list for a number", "parameters:\n  packet_period: [1]\n", 2, "must be a number"},
    {"packet period 0", "parameters:\n  packet_period: 0\n", 2, "out of range"},
    {"broadcast address", "parameters:\n  can_address: 65535\n", 2, "out of range"},
    {"negative temperature limit", "parameters:\n  upper_temperature_limit: -1\n", 2, "out of range"},
    {"unknown mask name", "parameters:\n  packets_streamed: [voltages, volts]\n", 2, "unknown name 'volts'"},
    {"mask name twice", "outputs: [payload, payload]\n", 1, "named twice"},
    {"mask with an undefined bit", "parameters:\n  packets_streamed: 0x20\n", 2, "outside the defined mask"},
    {"mask not a mask", "outputs: all\n", 1, "is not a mask"},
    {"mask number too big", "outputs: 256\n", 1, "whole number 0..255"},
    {"outputs bit 4", "outputs: 0x10\n", 1, "outputs"},
    {"generation yes", "generation_enabled: yes\n", 1, "true or false"},
    {"generation a list", "generation_enabled: [true]\n", 1, "true or false"},
    {"S0 bit for a newer firmware", "device:\n  firmware: \"1.14\"\nparameters:\n  power_up_state: [soa_management]\n",
     4, "needs firmware"},
    {"bad firmware", "device:\n  firmware: one\nparameters:\n  can_address: 2\n", 2, "not a firmware version"},
    {"serial out of range", "device:\n  serial: 70000\n", 2, "serial"},
    {"unknown header key", "device:\n  serial: 7\n  owner: me\n", 3, "unknown key 'owner' in device"},
    {"device not a mapping", "device: uav1\noutputs: []\n", 1, "device must be a mapping"},
    {"nothing to set", "device:\n  vehicle: uav1\n", 1, "nothing to compare"},
    {"YAML syntax", "parameters:\n  avionics_voltage: [24.0\n", 3, "YAML syntax error"},
    {"two documents", "outputs: [payload]\n---\noutputs: []\n", 3, "second YAML document"},
    {"vehicle too long", "device:\n  vehicle: a-vehicle-name-too-long\noutputs: []\n", 2, "longer than 15"},
    // Numbers in plain decimal only, as the service's config (interface.md 4.1): an integer
    // setting takes no fraction, and no setting another base.
    {"a fraction for an address", "parameters:\n  can_address: 1.5\n", 2, "'1.5' is not a whole number"},
    {"a whole limit written with a fraction", "parameters:\n  upper_temperature_limit: 80.0\n", 2,
     "is not a whole number"},
    {"an address with a leading 0", "parameters:\n  can_address: 010\n", 2, "is not a whole number"},
    {"hex for a voltage", "parameters:\n  avionics_voltage: 0x18\n", 2, "'0x18' is not a decimal number"},
    {"an exponent", "parameters:\n  packet_period: 5e-1\n", 2, "is not a decimal number"},
    {"a plus sign", "parameters:\n  payload_voltage: +22.0\n", 2, "is not a decimal number"},
    {"a fraction without its 0", "parameters:\n  cranking_time: .5\n", 2, "is not a decimal number"},
    {"hex for the header's address", "device:\n  address: 0x10\noutputs: []\n", 2, "is not a whole number"},
    {"a leading 0 for the serial", "device:\n  serial: 01001\n", 2, "is not a whole number"},
};

TEST(ConfigFile, MalformedFilesAreRefusedAtTheirLine) {
  static_assert(std::size(kMalformed) >= 34);
  for (const auto& m : kMalformed) {
    const auto f = read_config_file(m.text);
    ASSERT_FALSE(f.ok()) << m.what;
    EXPECT_EQ(f.error().line, m.line) << m.what << ": " << f.error().message;
    EXPECT_NE(f.error().message.find(m.says), std::string::npos) << m.what << ": " << f.error().message;
    EXPECT_EQ(describe(f.error(), "fleet.yaml").rfind("fleet.yaml:" + std::to_string(m.line) + ": ", 0), 0u)
        << m.what << ": " << describe(f.error(), "fleet.yaml");
  }
}

TEST(ConfigDiff, ItemByItemInUnits) {
  const auto f =
      read_config_file("parameters:\n  avionics_voltage: 22.0\n  cranking_time: 5.0\noutputs: [avionics_servo]\n");
  ASSERT_TRUE(f.ok());
  Settings device = full_settings();
  device[Setting::CrankingTime].reset();  // not read
  const auto d = differences(device, *f);
  ASSERT_EQ(d.size(), 3u);
  EXPECT_EQ(describe(d[0]), "avionics_voltage: device 24.0 V, file 22.0 V");
  EXPECT_EQ(d[0].line, 2);
  EXPECT_EQ(describe(d[1]), "cranking_time: device not read, file 5.0 s");
  EXPECT_EQ(describe(d[2]), "outputs: device avionics_servo,payload (0x03), file avionics_servo (0x01)");
  const auto missing = not_in_file(device, *f);
  EXPECT_EQ(missing.size(), 10u);  // 12 read of 13 (not cranking_time), 2 of them in the file
}

TEST(ApplyPlan, SafeOrderAndTheConfirmRules) {
  Settings device = full_settings();
  const auto f = read_config_file(
      "parameters:\n"
      "  can_address: 7\n"
      "  packets_streamed: [voltages]\n"
      "  avionics_voltage: 22.0\n"
      "  upper_temperature_limit: 0\n"
      "  power_up_state: [payload]\n"
      "outputs: [payload]\n"
      "generation_enabled: false\n");
  ASSERT_TRUE(f.ok()) << f.error().message;
  const auto plan = apply_plan(differences(device, *f));
  std::vector<std::string> order;
  for (const auto& c : plan) order.emplace_back(setting_name(c.setting));
  EXPECT_EQ(order, (std::vector<std::string>{"upper_temperature_limit", "power_up_state", "avionics_voltage",
                                             "generation_enabled", "outputs", "packets_streamed", "can_address"}));
  auto rule = [&](const char* name) {
    for (const auto& c : plan)
      if (setting_name(c.setting) == name) return c.confirm;
    return std::optional<service::ConfirmRule>();
  };
  EXPECT_EQ(rule("can_address"), service::ConfirmRule::SetCanAddress);
  EXPECT_EQ(rule("upper_temperature_limit"), service::ConfirmRule::ThermalShutdown);
  EXPECT_EQ(rule("power_up_state"), service::ConfirmRule::PowerUpAvionicsOff);
  EXPECT_EQ(rule("outputs"), service::ConfirmRule::DisableAvionics);
  EXPECT_EQ(rule("avionics_voltage"), std::nullopt);
  // Not 0, but without temperatures and status: the alarms that read them go blind.
  EXPECT_EQ(rule("packets_streamed"), service::ConfirmRule::BlindMonitoring);
  for (const auto& c : plan) EXPECT_EQ(c.from, *device[c.setting]) << setting_name(c.setting);

  const auto silent = read_config_file("parameters:\n  packets_streamed: none\n");
  const auto streaming_or_not = [](bool streaming) {
    service::DeviceUse u;
    u.streaming = streaming;
    return u;
  };
  ASSERT_TRUE(silent.ok());
  EXPECT_EQ(apply_plan(differences(device, *silent), streaming_or_not(true))[0].confirm,
            service::ConfirmRule::StopStreaming);
  EXPECT_EQ(apply_plan(differences(device, *silent), streaming_or_not(false))[0].confirm, std::nullopt);
}

TEST(ApplyPlan, EachChangeIsTheCommandThatSetsIt) {
  EXPECT_EQ(std::get<service::action::SetOutputs>(action_for(Setting::Outputs, 0x05)).mask, 0x05);
  EXPECT_TRUE(std::get<service::action::SetGeneration>(action_for(Setting::GenerationEnabled, 1)).enable);
  const auto p = std::get<service::action::SetParameter>(action_for(Setting::CrankingTime, 45));
  EXPECT_EQ(p.parameter, Parameter::CrankingTime);
  EXPECT_EQ(p.raw, 45u);
}

// A restore puts back only what the apply changed (docs/safety.md H11): a change whose value
// the device no longer holds was someone else's since, and is left as it is.
TEST(ApplyPlan, AnUndoRestoresOnlyWhereTheDeviceStillHoldsTheAppliedValue) {
  const Change c{Setting::AvionicsVoltage, 120, 220, 3, std::nullopt};
  struct Case {
    const char* what;
    std::optional<std::uint32_t> device_now;
    Undo undo;
  };
  const Case cases[] = {
      {"still the applied value", 220u, Undo::Restore},
      {"another writer's value", 180u, Undo::ChangedByAnother},
      {"put back by another writer already", 120u, Undo::ChangedByAnother},
      {"not read", std::nullopt, Undo::NotRead},
  };
  for (const auto& k : cases) EXPECT_EQ(undo_of(c, k.device_now), k.undo) << k.what;
}

}  // namespace
}  // namespace pmu::baseline
