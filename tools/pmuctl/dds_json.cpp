#include "pmuctl/dds_json.hpp"

#include <cmath>

namespace pmu::tools {
namespace {

// float -> the shortest decimal that reads back as the same float (12.3f -> 12.3, not
// 12.300000190734863); NaN (no sensor) -> null.
Json num(float v) {
  if (std::isnan(v)) return nullptr;
  char buf[32];
  for (int precision = 6; precision <= 9; ++precision) {
    std::snprintf(buf, sizeof buf, "%.*g", precision, static_cast<double>(v));
    if (std::strtof(buf, nullptr) == v) break;
  }
  return std::strtod(buf, nullptr);
}

// Bit `n` of a CANopen type's `received` (interface.md 3.1) decides whether the value is shown.
template <class V>
Json if_received(std::uint32_t received, unsigned n, const V& v) {
  return (received >> n) & 1u ? Json(v) : Json(nullptr);
}

}  // namespace

Json values_of(const pmu::Voltages& s) {
  return Json{{"avionics", num(s.avionics())},   {"output_28v", num(s.output_28v())}, {"payload", num(s.payload())},
              {"servo", num(s.servo())},         {"battery_a", num(s.battery_a())},   {"battery_b", num(s.battery_b())},
              {"generator", num(s.generator())}};
}

Json values_of(const pmu::Currents& s) {
  return Json{{"avionics", num(s.avionics())}, {"output_28v", num(s.output_28v())}, {"payload", num(s.payload())},
              {"servo", num(s.servo())},       {"battery_a", num(s.battery_a())},   {"battery_b", num(s.battery_b())}};
}

Json values_of(const pmu::BatteryEnergy& s) {
  return Json{{"battery_a_mah", s.battery_a_mah()}, {"battery_b_mah", s.battery_b_mah()}};
}

Json values_of(const pmu::Temperatures& s) {
  return Json{{"internal", num(s.internal())},   {"battery_a", num(s.battery_a())}, {"battery_b", num(s.battery_b())},
              {"generator", num(s.generator())}, {"starter", num(s.starter())}};
}

Json values_of(const pmu::Status& s) {
  return Json{{"generator_rpm", s.generator_rpm()},
              {"generation_enabled", s.generation_enabled()},
              {"thermal_shutdown", s.thermal_shutdown()},
              {"soa_shutdown", s.soa_shutdown()},
              {"start_button", s.start_button()},
              {"payload_shed", s.payload_shed()},
              {"starter_ready", s.starter_ready()},
              {"avionics_servo_on", s.avionics_servo_on()},
              {"payload_on", s.payload_on()},
              {"charger_a_on", s.charger_a_on()},
              {"charger_b_on", s.charger_b_on()}};
}

Json values_of(const pmu::Config& s) {
  return Json{{"avionics_voltage", num(s.avionics_voltage())},
              {"payload_voltage", num(s.payload_voltage())},
              {"servo_voltage", num(s.servo_voltage())},
              {"battery_voltage", num(s.battery_voltage())},
              {"packet_period", num(s.packet_period())},
              {"packets_streamed", s.packets_streamed()},
              {"temperature_offset", s.temperature_offset()},
              {"upper_temperature_limit", s.upper_temperature_limit()},
              {"power_up_state", s.power_up_state()},
              {"cranking_time", num(s.cranking_time())},
              {"can_address", s.can_address()},
              {"outputs", s.outputs()},
              {"generation_enabled", s.generation_enabled()}};
}

Json values_of(const pmu::DeviceInfo& s) {
  Json features = Json::array();
  for (const auto& f : s.features()) features.push_back(std::string(f));
  return Json{{"serial_number", s.serial_number()}, {"firmware_major", s.firmware_major()},
              {"firmware_minor", s.firmware_minor()}, {"build_year", s.build_year()},
              {"build_month", s.build_month()},     {"build_day", s.build_day()},
              {"features", features}};
}

const char* to_string(pmu::HealthState s) {
  switch (s) {
    case pmu::UNKNOWN: return "UNKNOWN";
    case pmu::ONLINE: return "ONLINE";
    case pmu::STALE: return "STALE";
    case pmu::OFFLINE: return "OFFLINE";
  }
  return "UNKNOWN";
}

const char* to_string(pmu::BusState s) {
  switch (s) {
    case pmu::UP: return "UP";
    case pmu::ERROR_WARNING: return "ERROR_WARNING";
    case pmu::ERROR_PASSIVE: return "ERROR_PASSIVE";
    case pmu::BUS_OFF: return "BUS_OFF";
    case pmu::DOWN: return "DOWN";
  }
  return "DOWN";
}

Json values_of(const pmu::Health& s) {
  return Json{{"state", to_string(s.state())},
              {"bus_state", to_string(s.bus_state())},
              {"last_frame_age", num(s.last_frame_age())},
              {"frames_received", s.frames_received()},
              {"frames_sent", s.frames_sent()},
              {"decode_errors", s.decode_errors()},
              {"bus_errors", s.bus_errors()},
              {"rx_dropped", s.rx_dropped()},
              {"timeouts", s.timeouts()},
              {"reconnects", s.reconnects()},
              {"publish_failures", s.publish_failures()}};
}

}  // namespace pmu::tools

namespace pmu::tools {

const char* to_string(pmu::DeviceKind k) {
  switch (k) {
    case pmu::KIND_PMU: return "pmu";
    case pmu::KIND_BATTERY: return "battery";
    case pmu::KIND_MPPT: return "mppt";
  }
  return "pmu";
}

Json values_of(const pmu::Battery& s) {
  const auto r = s.received();
  return Json{{"voltage", num(s.voltage())},
              {"current", num(s.current())},
              {"current_discharge", num(s.current_discharge())},
              {"current_charge", num(s.current_charge())},
              {"state_of_charge", num(s.state_of_charge())},
              {"time_to_go", num(s.time_to_go())},
              {"cell_temperature_high", num(s.cell_temperature_high())},
              {"cell_temperature_low", num(s.cell_temperature_low())},
              {"cell_voltage_high", num(s.cell_voltage_high())},
              {"cell_voltage_low", num(s.cell_voltage_low())},
              {"bms_state", if_received(r, 10, s.bms_state())},
              {"temperature_1", num(s.temperature_1())},
              {"temperature_2", num(s.temperature_2())},
              {"temperature_3", num(s.temperature_3())},
              {"temperature_4", num(s.temperature_4())},
              {"power_level", num(s.power_level())}};
}

Json values_of(const pmu::BatteryCells& s) {
  Json cells = Json::array();
  for (const auto& c : s.cells()) cells.push_back(Json{{"cell", c.cell()}, {"cell_voltage", num(c.cell_voltage())}});
  return Json{{"cells", cells}};
}

Json values_of(const pmu::Mppt& s) {
  const auto r = s.received();
  return Json{{"voltage_output_raw", num(s.voltage_output_raw())},
              {"current_output_raw", num(s.current_output_raw())},
              {"voltage_out_sw_raw", num(s.voltage_out_sw_raw())},
              {"mppt_state", if_received(r, 3, s.mppt_state())},
              {"safety_enabled", if_received(r, 4, s.safety_enabled())},
              {"pwm_enabled", if_received(r, 5, s.pwm_enabled())},
              {"temperature", num(s.temperature())},
              {"voltage_panel_1_raw", num(s.voltage_panel_1_raw())},
              {"current_panel_1_raw", num(s.current_panel_1_raw())},
              {"duty_cycle_panel_1", num(s.duty_cycle_panel_1())},
              {"channel_1_active", if_received(r, 10, s.channel_1_active())},
              {"voltage_panel_2_raw", num(s.voltage_panel_2_raw())},
              {"current_panel_2_raw", num(s.current_panel_2_raw())},
              {"duty_cycle_panel_2", num(s.duty_cycle_panel_2())},
              {"channel_2_active", if_received(r, 14, s.channel_2_active())},
              {"voltage_panel_3_raw", num(s.voltage_panel_3_raw())},
              {"current_panel_3_raw", num(s.current_panel_3_raw())},
              {"duty_cycle_panel_3", num(s.duty_cycle_panel_3())},
              {"channel_3_active", if_received(r, 18, s.channel_3_active())},
              {"voltage_panel_4_raw", num(s.voltage_panel_4_raw())},
              {"current_panel_4_raw", num(s.current_panel_4_raw())},
              {"duty_cycle_panel_4", num(s.duty_cycle_panel_4())},
              {"channel_4_active", if_received(r, 22, s.channel_4_active())}};
}

}  // namespace pmu::tools
