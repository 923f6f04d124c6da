#include "pmu/mavlink/messages.hpp"

#include "payload_bytes.hpp"

// Offsets: the wire order of each definition (fields sorted by type size, largest first, in
// declaration order within a size; extensions after, in declaration order).

namespace pmu::mavlink {

using detail::get;
using detail::get_chars;
using detail::put;
using detail::put_chars;

void Heartbeat::pack(Payload& out) const {
  put(out, 0, custom_mode);
  put(out, 4, type);
  put(out, 5, autopilot);
  put(out, 6, base_mode);
  put(out, 7, system_status);
  put(out, 8, mavlink_version);
}

Heartbeat Heartbeat::unpack(const Payload& in) {
  Heartbeat m;
  m.custom_mode = get<std::uint32_t>(in, 0);
  m.type = get<std::uint8_t>(in, 4);
  m.autopilot = get<std::uint8_t>(in, 5);
  m.base_mode = get<std::uint8_t>(in, 6);
  m.system_status = get<std::uint8_t>(in, 7);
  m.mavlink_version = get<std::uint8_t>(in, 8);
  return m;
}

void ParamRequestRead::pack(Payload& out) const {
  put(out, 0, param_index);
  put(out, 2, target_system);
  put(out, 3, target_component);
  put_chars(out, 4, 16, param_id);
}

ParamRequestRead ParamRequestRead::unpack(const Payload& in) {
  ParamRequestRead m;
  m.param_index = get<std::int16_t>(in, 0);
  m.target_system = get<std::uint8_t>(in, 2);
  m.target_component = get<std::uint8_t>(in, 3);
  m.param_id = get_chars(in, 4, 16);
  return m;
}

void ParamRequestList::pack(Payload& out) const {
  put(out, 0, target_system);
  put(out, 1, target_component);
}

ParamRequestList ParamRequestList::unpack(const Payload& in) {
  ParamRequestList m;
  m.target_system = get<std::uint8_t>(in, 0);
  m.target_component = get<std::uint8_t>(in, 1);
  return m;
}

void ParamValue::pack(Payload& out) const {
  put(out, 0, param_value);
  put(out, 4, param_count);
  put(out, 6, param_index);
  put_chars(out, 8, 16, param_id);
  put(out, 24, param_type);
}

ParamValue ParamValue::unpack(const Payload& in) {
  ParamValue m;
  m.param_value = get<float>(in, 0);
  m.param_count = get<std::uint16_t>(in, 4);
  m.param_index = get<std::uint16_t>(in, 6);
  m.param_id = get_chars(in, 8, 16);
  m.param_type = get<std::uint8_t>(in, 24);
  return m;
}

void ParamSet::pack(Payload& out) const {
  put(out, 0, param_value);
  put(out, 4, target_system);
  put(out, 5, target_component);
  put_chars(out, 6, 16, param_id);
  put(out, 22, param_type);
}

ParamSet ParamSet::unpack(const Payload& in) {
  ParamSet m;
  m.param_value = get<float>(in, 0);
  m.target_system = get<std::uint8_t>(in, 4);
  m.target_component = get<std::uint8_t>(in, 5);
  m.param_id = get_chars(in, 6, 16);
  m.param_type = get<std::uint8_t>(in, 22);
  return m;
}

void CommandLong::pack(Payload& out) const {
  for (std::size_t i = 0; i < param.size(); ++i) put(out, 4 * i, param[i]);
  put(out, 28, command);
  put(out, 30, target_system);
  put(out, 31, target_component);
  put(out, 32, confirmation);
}

CommandLong CommandLong::unpack(const Payload& in) {
  CommandLong m;
  for (std::size_t i = 0; i < m.param.size(); ++i) m.param[i] = get<float>(in, 4 * i);
  m.command = get<std::uint16_t>(in, 28);
  m.target_system = get<std::uint8_t>(in, 30);
  m.target_component = get<std::uint8_t>(in, 31);
  m.confirmation = get<std::uint8_t>(in, 32);
  return m;
}

void CommandAck::pack(Payload& out) const {
  put(out, 0, command);
  put(out, 2, result);
  put(out, 3, progress);
  put(out, 4, result_param2);
  put(out, 8, target_system);
  put(out, 9, target_component);
}

CommandAck CommandAck::unpack(const Payload& in) {
  CommandAck m;
  m.command = get<std::uint16_t>(in, 0);
  m.result = get<std::uint8_t>(in, 2);
  m.progress = get<std::uint8_t>(in, 3);
  m.result_param2 = get<std::int32_t>(in, 4);
  m.target_system = get<std::uint8_t>(in, 8);
  m.target_component = get<std::uint8_t>(in, 9);
  return m;
}

void BatteryStatus::pack(Payload& out) const {
  put(out, 0, current_consumed);
  put(out, 4, energy_consumed);
  put(out, 8, temperature);
  for (std::size_t i = 0; i < voltages.size(); ++i) put(out, 10 + 2 * i, voltages[i]);
  put(out, 30, current_battery);
  put(out, 32, id);
  put(out, 33, battery_function);
  put(out, 34, type);
  put(out, 35, battery_remaining);
  put(out, 36, time_remaining);
  put(out, 40, charge_state);
  for (std::size_t i = 0; i < voltages_ext.size(); ++i) put(out, 41 + 2 * i, voltages_ext[i]);
  put(out, 49, mode);
  put(out, 50, fault_bitmask);
}

BatteryStatus BatteryStatus::unpack(const Payload& in) {
  BatteryStatus m;
  m.current_consumed = get<std::int32_t>(in, 0);
  m.energy_consumed = get<std::int32_t>(in, 4);
  m.temperature = get<std::int16_t>(in, 8);
  for (std::size_t i = 0; i < m.voltages.size(); ++i) m.voltages[i] = get<std::uint16_t>(in, 10 + 2 * i);
  m.current_battery = get<std::int16_t>(in, 30);
  m.id = get<std::uint8_t>(in, 32);
  m.battery_function = get<std::uint8_t>(in, 33);
  m.type = get<std::uint8_t>(in, 34);
  m.battery_remaining = get<std::int8_t>(in, 35);
  m.time_remaining = get<std::int32_t>(in, 36);
  m.charge_state = get<std::uint8_t>(in, 40);
  for (std::size_t i = 0; i < m.voltages_ext.size(); ++i) m.voltages_ext[i] = get<std::uint16_t>(in, 41 + 2 * i);
  m.mode = get<std::uint8_t>(in, 49);
  m.fault_bitmask = get<std::uint32_t>(in, 50);
  return m;
}

void Statustext::pack(Payload& out) const {
  put(out, 0, severity);
  put_chars(out, 1, kTextLength, text);
  put(out, 51, id);
  put(out, 53, chunk_seq);
}

Statustext Statustext::unpack(const Payload& in) {
  Statustext m;
  m.severity = get<std::uint8_t>(in, 0);
  m.text = get_chars(in, 1, kTextLength);
  m.id = get<std::uint16_t>(in, 51);
  m.chunk_seq = get<std::uint8_t>(in, 53);
  return m;
}

void GeneratorStatus::pack(Payload& out) const {
  put(out, 0, status);
  put(out, 8, battery_current);
  put(out, 12, load_current);
  put(out, 16, power_generated);
  put(out, 20, bus_voltage);
  put(out, 24, bat_current_setpoint);
  put(out, 28, runtime);
  put(out, 32, time_until_maintenance);
  put(out, 36, generator_speed);
  put(out, 38, rectifier_temperature);
  put(out, 40, generator_temperature);
}

GeneratorStatus GeneratorStatus::unpack(const Payload& in) {
  GeneratorStatus m;
  m.status = get<std::uint64_t>(in, 0);
  m.battery_current = get<float>(in, 8);
  m.load_current = get<float>(in, 12);
  m.power_generated = get<float>(in, 16);
  m.bus_voltage = get<float>(in, 20);
  m.bat_current_setpoint = get<float>(in, 24);
  m.runtime = get<std::uint32_t>(in, 28);
  m.time_until_maintenance = get<std::int32_t>(in, 32);
  m.generator_speed = get<std::uint16_t>(in, 36);
  m.rectifier_temperature = get<std::int16_t>(in, 38);
  m.generator_temperature = get<std::int16_t>(in, 40);
  return m;
}

void RelayStatus::pack(Payload& out) const {
  put(out, 0, time_boot_ms);
  put(out, 4, on);
  put(out, 6, present);
}

RelayStatus RelayStatus::unpack(const Payload& in) {
  RelayStatus m;
  m.time_boot_ms = get<std::uint32_t>(in, 0);
  m.on = get<std::uint16_t>(in, 4);
  m.present = get<std::uint16_t>(in, 6);
  return m;
}

}  // namespace pmu::mavlink
