#pragma once
// The messages of pmu::mavlink as the XML defines them (mavlink/mavlink
// message_definitions/v1.0, the commit in mavlink/README.md): each field's C type, name,
// array length and whether it follows <extensions/>, in declaration order. The tests derive
// CRC_EXTRA, wire order, offsets and lengths from these with mavgen's rules and compare them
// with the library's table and pack functions.

#include <cstdint>
#include <string>
#include <vector>

namespace pmu::mavlink::test {

struct FieldDef {
  std::string type;  // C type of one element: uint8_t, int16_t, float, char, ...
  std::string name;
  unsigned array_length = 0;  // 0: not an array
  bool extension = false;
};

struct MessageDef {
  std::uint32_t id;
  std::string name;
  std::vector<FieldDef> fields;
  // Published CRC_EXTRA (shared/research mavlink.md, computed there from the same XML).
  unsigned published_crc_extra;
};

inline const std::vector<MessageDef>& definitions() {
  static const std::vector<MessageDef> defs = {
      {0,
       "HEARTBEAT",
       {{"uint8_t", "type"},
        {"uint8_t", "autopilot"},
        {"uint8_t", "base_mode"},
        {"uint32_t", "custom_mode"},
        {"uint8_t", "system_status"},
        {"uint8_t", "mavlink_version"}},
       50},
      {20,
       "PARAM_REQUEST_READ",
       {{"uint8_t", "target_system"},
        {"uint8_t", "target_component"},
        {"char", "param_id", 16},
        {"int16_t", "param_index"}},
       214},
      {21, "PARAM_REQUEST_LIST", {{"uint8_t", "target_system"}, {"uint8_t", "target_component"}}, 159},
      {22,
       "PARAM_VALUE",
       {{"char", "param_id", 16},
        {"float", "param_value"},
        {"uint8_t", "param_type"},
        {"uint16_t", "param_count"},
        {"uint16_t", "param_index"}},
       220},
      {23,
       "PARAM_SET",
       {{"uint8_t", "target_system"},
        {"uint8_t", "target_component"},
        {"char", "param_id", 16},
        {"float", "param_value"},
        {"uint8_t", "param_type"}},
       168},
      {76,
       "COMMAND_LONG",
       {{"uint8_t", "target_system"},
        {"uint8_t", "target_component"},
        {"uint16_t", "command"},
        {"uint8_t", "confirmation"},
        {"float", "param1"},
        {"float", "param2"},
        {"float", "param3"},
        {"float", "param4"},
        {"float", "param5"},
        {"float", "param6"},
        {"float", "param7"}},
       152},
      {77,
       "COMMAND_ACK",
       {{"uint16_t", "command"},
        {"uint8_t", "result"},
        {"uint8_t", "progress", 0, true},
        {"int32_t", "result_param2", 0, true},
        {"uint8_t", "target_system", 0, true},
        {"uint8_t", "target_component", 0, true}},
       143},
      {147,
       "BATTERY_STATUS",
       {{"uint8_t", "id"},
        {"uint8_t", "battery_function"},
        {"uint8_t", "type"},
        {"int16_t", "temperature"},
        {"uint16_t", "voltages", 10},
        {"int16_t", "current_battery"},
        {"int32_t", "current_consumed"},
        {"int32_t", "energy_consumed"},
        {"int8_t", "battery_remaining"},
        {"int32_t", "time_remaining", 0, true},
        {"uint8_t", "charge_state", 0, true},
        {"uint16_t", "voltages_ext", 4, true},
        {"uint8_t", "mode", 0, true},
        {"uint32_t", "fault_bitmask", 0, true}},
       154},
      {253,
       "STATUSTEXT",
       {{"uint8_t", "severity"}, {"char", "text", 50}, {"uint16_t", "id", 0, true}, {"uint8_t", "chunk_seq", 0, true}},
       83},
      {373,
       "GENERATOR_STATUS",
       {{"uint64_t", "status"},
        {"uint16_t", "generator_speed"},
        {"float", "battery_current"},
        {"float", "load_current"},
        {"float", "power_generated"},
        {"float", "bus_voltage"},
        {"int16_t", "rectifier_temperature"},
        {"float", "bat_current_setpoint"},
        {"int16_t", "generator_temperature"},
        {"uint32_t", "runtime"},
        {"int32_t", "time_until_maintenance"}},
       117},
      {376, "RELAY_STATUS", {{"uint32_t", "time_boot_ms"}, {"uint16_t", "on"}, {"uint16_t", "present"}}, 199},
  };
  return defs;
}

}  // namespace pmu::mavlink::test
