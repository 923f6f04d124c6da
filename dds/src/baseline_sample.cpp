#include "pmu/dds/baseline_sample.hpp"

#include <cmath>

namespace pmu::service {
namespace {

using baseline::Setting;

// The IDL's float back to the raw value: each scaled value is a whole number of its steps.
std::uint32_t raw_of(codec::Parameter p, double value) {
  const auto& spec = codec::spec_of(p);
  if (!std::isfinite(value) || value < 0) return 0;
  return static_cast<std::uint32_t>(std::lround(value * spec.divisor));
}

float value_of(codec::Parameter p, const std::optional<std::uint32_t>& raw) {
  return raw ? static_cast<float>(codec::parameter_value(p, *raw)) : 0.0f;
}

std::uint8_t octet_of(const std::optional<std::uint32_t>& raw) {
  return static_cast<std::uint8_t>(raw.value_or(0) & 0xFF);
}

// One accessor list for both directions, in Setting's order.
template <class Sample, class Visit>
void each_setting(Sample& s, Visit&& v) {
  v(Setting::AvionicsVoltage, s.avionics_voltage());
  v(Setting::PayloadVoltage, s.payload_voltage());
  v(Setting::ServoVoltage, s.servo_voltage());
  v(Setting::BatteryVoltage, s.battery_voltage());
  v(Setting::PacketPeriod, s.packet_period());
  v(Setting::PacketsStreamed, s.packets_streamed());
  v(Setting::TemperatureOffset, s.temperature_offset());
  v(Setting::UpperTemperatureLimit, s.upper_temperature_limit());
  v(Setting::PowerUpState, s.power_up_state());
  v(Setting::CrankingTime, s.cranking_time());
  v(Setting::CanAddress, s.can_address());
  v(Setting::Outputs, s.outputs());
  v(Setting::GenerationEnabled, s.generation_enabled());
}

// A field's raw value: a float by its parameter's step, an integer or flag as it is.
std::uint32_t raw_field(Setting s, float v) { return raw_of(*baseline::parameter_of(s), v); }
std::uint32_t raw_field(Setting, std::uint8_t v) { return v; }
std::uint32_t raw_field(Setting, std::uint16_t v) { return v; }
std::uint32_t raw_field(Setting, bool v) { return v ? 1u : 0u; }

void set_field(Setting s, float& f, const std::optional<std::uint32_t>& raw) {
  f = value_of(*baseline::parameter_of(s), raw);
}
void set_field(Setting, std::uint8_t& f, const std::optional<std::uint32_t>& raw) { f = octet_of(raw); }
void set_field(Setting, std::uint16_t& f, const std::optional<std::uint32_t>& raw) {
  f = static_cast<std::uint16_t>(raw.value_or(0) & 0xFFFF);
}
void set_field(Setting, bool& f, const std::optional<std::uint32_t>& raw) { f = raw.value_or(0) != 0; }

}  // namespace

pmu::v5::Baseline baseline_sample(const std::string& vehicle, const std::string& bus, std::uint16_t address,
                                  const std::string& file, const std::optional<baseline::ConfigFile>& content) {
  pmu::v5::Baseline s;
  s.vehicle(vehicle);
  s.bus(bus);
  s.address(address);
  s.file(file.substr(0, baseline::kMaxPathBytes));
  if (!content) return s;
  const auto& f = *content;
  s.has_serial(f.header.serial.has_value());
  s.serial(f.header.serial.value_or(0));
  s.has_min_firmware(f.header.min_firmware.has_value());
  if (f.header.min_firmware) {
    s.min_firmware_major(f.header.min_firmware->major);
    s.min_firmware_minor(f.header.min_firmware->minor);
  }
  std::uint16_t present = 0;
  each_setting(s, [&](Setting setting, auto& field) {
    const auto& raw = f.settings[setting];
    if (raw) present = static_cast<std::uint16_t>(present | (1u << static_cast<unsigned>(setting)));
    set_field(setting, field, raw);
  });
  s.present(present);
  return s;
}

baseline::ConfigFile config_file_of(const pmu::v5::Baseline& sample) {
  baseline::ConfigFile f;
  f.header.vehicle = sample.vehicle();
  f.header.bus = sample.bus();
  f.header.address = sample.address();
  if (sample.has_serial()) f.header.serial = sample.serial();
  if (sample.has_min_firmware())
    f.header.min_firmware = codec::FirmwareVersion{sample.min_firmware_major(), sample.min_firmware_minor()};
  each_setting(sample, [&](Setting setting, const auto& field) {
    if (sample.present() & (1u << static_cast<unsigned>(setting))) f.settings[setting] = raw_field(setting, field);
  });
  return f;
}

baseline::Settings settings_of(const pmu::v5::Config& config) {
  baseline::Settings s;
  each_setting(config, [&](Setting setting, const auto& field) { s[setting] = raw_field(setting, field); });
  return s;
}

}  // namespace pmu::service
