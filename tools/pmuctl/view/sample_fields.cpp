#include "pmuctl/view/sample_fields.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <limits>

#include "pmu/codec/parameters.hpp"
#include "pmu/codec/telemetry.hpp"
#include "pmu/idl_tables/canopen_values.hpp"
#include "pmuctl/decode/frame_fields.hpp"
#include "pmuctl/view/mask_names.hpp"

namespace pmu::tools {
namespace {

SampleField none(std::string_view name, const char* word) { return {std::string(name), nullptr, word, ""}; }

SampleField real(std::string_view name, double v, std::string_view unit, const char* nan_word) {
  if (std::isnan(v)) return none(name, nan_word);
  if (std::isinf(v)) return {std::string(name), nullptr, v > 0 ? "inf" : "-inf", std::string(unit)};  // JSON has none
  const std::string t = shortest(static_cast<float>(v));
  // A whole number keeps ".0", as the JSON prints it: a measurement, not a count.
  const std::string text = t.find_first_of(".e") == std::string::npos ? t + ".0" : t;
  return {std::string(name), Json(std::strtod(t.c_str(), nullptr)), text, std::string(unit)};
}

SampleField integer(std::string_view name, std::int64_t v, std::string_view unit = {}) {
  return {std::string(name), Json(v), std::to_string(v), std::string(unit)};
}

SampleField flag(std::string_view name, bool v) { return {std::string(name), Json(v), v ? "yes" : "no", ""}; }

// A PMU packet's values, with the names and units of the codec's table for it, in its order; the
// DDS type has the same fields in the same order (idl/telemetry.idl).
template <class Packet, class V, std::size_t N>
SampleFields measured(const std::array<V, N>& values, const char* nan_word) {
  static_assert(N == codec::Telemetry<Packet>::fields.size());
  SampleFields out;
  for (std::size_t i = 0; i < N; ++i) {
    const auto& f = codec::Telemetry<Packet>::fields[i];
    if constexpr (std::is_floating_point_v<V>)
      out.push_back(real(f.name, values[i], f.unit, nan_word));
    else
      out.push_back(integer(f.name, values[i], f.unit));
  }
  return out;
}

// The decode formatter's fields, for a packet without a table (0x04).
struct Collect final : FieldSink {
  SampleFields out;
  void field(std::string_view name, const FieldValue& v, std::string_view unit) override {
    switch (v.kind) {
      case FieldValue::Kind::Number: out.push_back(real(name, v.number, unit, kNoReading)); break;
      case FieldValue::Kind::Integer: out.push_back(integer(name, v.integer, unit)); break;
      case FieldValue::Kind::Boolean: out.push_back(flag(name, v.boolean)); break;
    }
  }
};

// A battery's or MPPT's value in slot `bit` of the service's table (its `received` bit):
// "-"/null unless received; a float without a unit is a raw count, shown as an integer.
template <std::size_t N>
SampleField canopen_value(const service::CanOpenValue (&table)[N], std::size_t bit, std::uint32_t received, double v,
                          bool is_float, bool is_bool) {
  const auto& c = table[bit];
  if (!((received >> bit) & 1u) || std::isnan(v)) return none(c.name, kNotReceived);
  if (is_bool) return flag(c.name, v != 0);
  // Beyond int64 (no device sends that, a foreign writer might) llround is undefined.
  if ((is_float && !c.unit.empty()) || !(std::fabs(v) < 9e18)) return real(c.name, v, c.unit, kNotReceived);
  return integer(c.name, std::llround(v), c.unit);
}

}  // namespace

std::string shortest(float v) {
  char buf[32];
  for (int precision = 6; precision <= 9; ++precision) {
    std::snprintf(buf, sizeof buf, "%.*g", precision, static_cast<double>(v));
    if (std::strtof(buf, nullptr) == v) break;
  }
  return buf;
}

const SampleField* find_field(const SampleFields& fields, std::string_view name) {
  for (const auto& f : fields)
    if (f.name == name) return &f;
  return nullptr;
}

Json json_of(const SampleFields& fields) {
  Json j = Json::object();
  for (const auto& f : fields) j[f.name] = f.json;
  return j;
}

std::string text_with_unit(const SampleField& f, bool compact) {
  if (f.unit.empty()) return f.text;
  return f.text + (compact ? "" : " ") + f.unit;
}

SampleFields fields_of(const pmu::v5::Voltages& s) {
  return measured<codec::Voltages>(std::array<double, 7>{s.avionics(), s.output_28v(), s.payload(), s.servo(),
                                                         s.battery_a(), s.battery_b(), s.generator()},
                                   kNoReading);
}

SampleFields fields_of(const pmu::v5::Currents& s) {
  return measured<codec::Currents>(
      std::array<double, 6>{s.avionics(), s.output_28v(), s.payload(), s.servo(), s.battery_a(), s.battery_b()},
      kNoReading);
}

SampleFields fields_of(const pmu::v5::BatteryEnergy& s) {
  return measured<codec::BatteryEnergy>(std::array<std::int64_t, 2>{s.battery_a_mah(), s.battery_b_mah()}, "");
}

SampleFields fields_of(const pmu::v5::Temperatures& s) {
  return measured<codec::Temperatures>(
      std::array<double, 5>{s.internal(), s.battery_a(), s.battery_b(), s.generator(), s.starter()}, kNoSensor);
}

SampleFields fields_of(const pmu::v5::Status& s) {
  codec::Status st;
  // NaN is no reading (below); otherwise a whole number of rpm below 65535 (the PMU's 16 bits).
  const float rpm = s.generator_rpm();
  st.generator_rpm = std::isnan(rpm) ? 0 : static_cast<std::uint16_t>(std::lround(std::clamp(rpm, 0.0f, 65534.0f)));
  st.generation_enabled = s.generation_enabled();
  st.thermal_shutdown = s.thermal_shutdown();
  st.soa_shutdown = s.soa_shutdown();
  st.start_button = s.start_button();
  st.payload_shed = s.payload_shed();
  st.starter_ready = s.starter_ready();
  st.outputs = static_cast<std::uint8_t>((s.avionics_servo_on() ? codec::output_bit::AvionicsServo : 0) |
                                         (s.payload_on() ? codec::output_bit::Payload : 0) |
                                         (s.charger_a_on() ? codec::output_bit::ChargerA : 0) |
                                         (s.charger_b_on() ? codec::output_bit::ChargerB : 0));
  codec::PmuMessage m;
  m.packet = codec::PacketId::Status;
  m.payload = st;
  Collect c;
  visit_fields(m, c);
  for (auto& f : c.out)
    if (f.name == "generator_rpm" && std::isnan(rpm)) f = none(f.name, kNoReading);
  return c.out;
}

SampleFields fields_of(const pmu::v5::Config& s) {
  SampleFields out;
  for (const auto& spec : codec::parameter_table()) {
    using P = codec::Parameter;
    switch (spec.parameter) {
      case P::AvionicsVoltage: out.push_back(real(spec.name, s.avionics_voltage(), spec.unit, kNotReceived)); break;
      case P::PayloadVoltage: out.push_back(real(spec.name, s.payload_voltage(), spec.unit, kNotReceived)); break;
      case P::ServoVoltage: out.push_back(real(spec.name, s.servo_voltage(), spec.unit, kNotReceived)); break;
      case P::BatteryVoltage: out.push_back(real(spec.name, s.battery_voltage(), spec.unit, kNotReceived)); break;
      case P::PacketPeriod: out.push_back(real(spec.name, s.packet_period(), spec.unit, kNotReceived)); break;
      case P::PacketsStreamed: out.push_back(integer(spec.name, s.packets_streamed())); break;
      case P::TemperatureOffset: out.push_back(integer(spec.name, s.temperature_offset(), spec.unit)); break;
      case P::UpperTemperatureLimit: {
        auto f = integer(spec.name, s.upper_temperature_limit(), spec.unit);
        // Table 15: 0 forces thermal shutdown, 255 disables it.
        if (s.upper_temperature_limit() == 0) f.text = "0 (forces thermal shutdown)", f.unit.clear();
        if (s.upper_temperature_limit() == 255) f.text = "255 (thermal shutdown disabled)", f.unit.clear();
        out.push_back(f);
        break;
      }
      case P::PowerUpState: out.push_back(integer(spec.name, s.power_up_state())); break;
      case P::CrankingTime: {
        auto f = real(spec.name, s.cranking_time(), spec.unit, kNotReceived);
        if (s.cranking_time() == 0) f.text = "0.0 (no timeout)", f.unit.clear();  // table 17
        out.push_back(f);
        break;
      }
      case P::CanAddress: out.push_back(integer(spec.name, s.can_address(), spec.unit)); break;
    }
  }
  out.push_back(integer("outputs", s.outputs()));
  out.push_back(flag("generation_enabled", s.generation_enabled()));
  for (auto& f : out)
    if (const auto* m = mask_names(f.name))
      f.text = codec::mask_text(m->bits, m->count, static_cast<std::uint8_t>(f.json.get<int>()));
  return out;
}

SampleFields fields_of(const pmu::v5::DeviceInfo& s) {
  Json features = Json::array();
  std::string text;
  for (const auto& f : s.features()) {
    features.push_back(std::string(f));
    text += (text.empty() ? "" : ",") + std::string(f);
  }
  return {integer("serial_number", s.serial_number()),
          integer("firmware_major", s.firmware_major()),
          integer("firmware_minor", s.firmware_minor()),
          integer("build_year", s.build_year()),
          integer("build_month", s.build_month()),
          integer("build_day", s.build_day()),
          {"features", features, text.empty() ? "none" : text, ""}};
}

SampleFields fields_of(const pmu::v5::Health& s) {
  SampleField age = std::isnan(s.last_frame_age()) ? none("last_frame_age", kNever)
                                                   : real("last_frame_age", s.last_frame_age(), "s", kNever);
  if (age.json.is_number()) {
    char tenths[32];  // the service's clock, not a measurement: 0.1 s is enough
    std::snprintf(tenths, sizeof tenths, "%.1f", age.json.get<double>());
    age.text = tenths;
  }
  return {{"state", to_string(s.state()), to_string(s.state()), ""},
          {"bus_state", to_string(s.bus_state()), to_string(s.bus_state()), ""},
          age,
          integer("frames_received", static_cast<std::int64_t>(s.frames_received())),
          integer("frames_sent", static_cast<std::int64_t>(s.frames_sent())),
          integer("decode_errors", static_cast<std::int64_t>(s.decode_errors())),
          integer("bus_errors", static_cast<std::int64_t>(s.bus_errors())),
          integer("rx_dropped", static_cast<std::int64_t>(s.rx_dropped())),
          integer("timeouts", static_cast<std::int64_t>(s.timeouts())),
          integer("reconnects", static_cast<std::int64_t>(s.reconnects())),
          integer("publish_failures", static_cast<std::int64_t>(s.publish_failures()))};
}

SampleFields fields_of(const pmu::v5::Battery& s) {
  // In the order of service::kBatteryValues (= IDL order = `received` bits).
  const std::array<double, service::kBatteryValueCount> v{s.voltage(),
                                                          s.current(),
                                                          s.current_discharge(),
                                                          s.current_charge(),
                                                          s.state_of_charge(),
                                                          s.time_to_go(),
                                                          s.cell_temperature_high(),
                                                          s.cell_temperature_low(),
                                                          s.cell_voltage_high(),
                                                          s.cell_voltage_low(),
                                                          s.bms_state(),
                                                          s.temperature_1(),
                                                          s.temperature_2(),
                                                          s.temperature_3(),
                                                          s.temperature_4(),
                                                          s.power_level()};
  SampleFields out;
  for (std::size_t i = 0; i < v.size(); ++i) {
    const bool is_integer = service::kBatteryValues[i].name == "bms_state";
    auto f = canopen_value(service::kBatteryValues, i, s.received(), v[i], !is_integer, false);
    // Received, and NaN: the battery sent its field's top, which it sends while not discharging.
    if (f.name == "time_to_go" && ((s.received() >> i) & 1u) && std::isnan(v[i])) f = none(f.name, kNotDischarging);
    out.push_back(f);
  }
  return out;
}

SampleFields fields_of(const pmu::v5::BatteryCells& s) {
  Json cells = Json::array();
  double lo = INFINITY, hi = -INFINITY;
  for (const auto& c : s.cells()) {
    cells.push_back(Json{{"cell", c.cell()}, {"cell_voltage", real("", c.cell_voltage(), "", "").json}});
    if (std::isnan(c.cell_voltage())) continue;
    lo = std::min(lo, static_cast<double>(c.cell_voltage()));
    hi = std::max(hi, static_cast<double>(c.cell_voltage()));
  }
  const std::size_t n = s.cells().size();
  std::string text = n == 0 ? std::string("none received") : std::to_string(n) + (n == 1 ? " cell" : " cells");
  if (lo <= hi) {
    char buf[64];
    std::snprintf(buf, sizeof buf, " %.3f..%.3f V", lo, hi);
    text += buf;
  }
  return {{"cells", cells, text, ""}};
}

SampleFields fields_of(const pmu::v5::Mppt& s) {
  // In the order of service::kMpptValues (= IDL order = `received` bits).
  const std::array<double, service::kMpptValueCount> v{
      s.voltage_output_raw(),  s.current_output_raw(), s.voltage_out_sw_raw(), s.mppt_state(),
      s.safety_enabled(),      s.pwm_enabled(),        s.temperature(),        s.voltage_panel_1_raw(),
      s.current_panel_1_raw(), s.duty_cycle_panel_1(), s.channel_1_active(),   s.voltage_panel_2_raw(),
      s.current_panel_2_raw(), s.duty_cycle_panel_2(), s.channel_2_active(),   s.voltage_panel_3_raw(),
      s.current_panel_3_raw(), s.duty_cycle_panel_3(), s.channel_3_active(),   s.voltage_panel_4_raw(),
      s.current_panel_4_raw(), s.duty_cycle_panel_4(), s.channel_4_active()};
  SampleFields out;
  for (std::size_t i = 0; i < v.size(); ++i) {
    const std::string_view name = service::kMpptValues[i].name;
    const bool is_bool = name == "safety_enabled" || name == "pwm_enabled";
    out.push_back(canopen_value(service::kMpptValues, i, s.received(), v[i], true, is_bool));
  }
  return out;
}

}  // namespace pmu::tools
