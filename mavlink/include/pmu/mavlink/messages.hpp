#pragma once
// The messages pmu-mavlink sends and receives, each a plain struct with the fields of its
// definition (common.xml / minimal.xml, names as there) and
//   void pack(Payload&) const          all fields at their wire offsets (the payload's
//                                      max_length bytes; FrameWriter truncates the zeros)
//   static T unpack(const Payload&)    total: reads a Frame's payload, whose bytes beyond
//                                      what was sent are zero, so a short payload gives 0
//                                      for the fields it lacks, as the spec says
// decode<T>(frame) gives the message when the frame carries that id.
// char[n] fields are std::string: pack writes at most n bytes (no terminator when exactly
// n, as the definitions allow), unpack reads up to the first NUL or n bytes.
// Defaults are the definitions' "not provided" values (constants.hpp) where one exists.

#include <array>
#include <cstdint>
#include <optional>
#include <string>

#include "pmu/mavlink/constants.hpp"
#include "pmu/mavlink/frame.hpp"
#include "pmu/mavlink/message_table.hpp"

namespace pmu::mavlink {

template <std::size_t N>
constexpr std::array<std::uint16_t, N> filled(std::uint16_t value) {
  std::array<std::uint16_t, N> a{};
  for (auto& v : a) v = value;
  return a;
}

struct Heartbeat {
  static constexpr std::uint32_t kId = msgid::kHeartbeat;
  std::uint8_t type = mav_type::kGeneric;
  std::uint8_t autopilot = mav_autopilot::kInvalid;
  std::uint8_t base_mode = 0;
  std::uint32_t custom_mode = 0;
  std::uint8_t system_status = mav_state::kUninit;
  std::uint8_t mavlink_version = kMavlinkVersion;

  void pack(Payload& out) const;
  static Heartbeat unpack(const Payload& in);
};

struct ParamRequestRead {
  static constexpr std::uint32_t kId = msgid::kParamRequestRead;
  std::uint8_t target_system = 0;
  std::uint8_t target_component = 0;
  std::string param_id;
  std::int16_t param_index = not_provided::kParamIndex;

  void pack(Payload& out) const;
  static ParamRequestRead unpack(const Payload& in);
};

struct ParamRequestList {
  static constexpr std::uint32_t kId = msgid::kParamRequestList;
  std::uint8_t target_system = 0;
  std::uint8_t target_component = 0;

  void pack(Payload& out) const;
  static ParamRequestList unpack(const Payload& in);
};

struct ParamValue {
  static constexpr std::uint32_t kId = msgid::kParamValue;
  std::string param_id;
  float param_value = 0.0F;
  std::uint8_t param_type = mav_param_type::kReal32;
  std::uint16_t param_count = 0;
  std::uint16_t param_index = 0;

  void pack(Payload& out) const;
  static ParamValue unpack(const Payload& in);
};

struct ParamSet {
  static constexpr std::uint32_t kId = msgid::kParamSet;
  std::uint8_t target_system = 0;
  std::uint8_t target_component = 0;
  std::string param_id;
  float param_value = 0.0F;
  std::uint8_t param_type = mav_param_type::kReal32;

  void pack(Payload& out) const;
  static ParamSet unpack(const Payload& in);
};

struct CommandLong {
  static constexpr std::uint32_t kId = msgid::kCommandLong;
  std::uint8_t target_system = 0;
  std::uint8_t target_component = 0;
  std::uint16_t command = 0;
  std::uint8_t confirmation = 0;
  std::array<float, 7> param{};  // param1..param7

  void pack(Payload& out) const;
  static CommandLong unpack(const Payload& in);
};

struct CommandAck {
  static constexpr std::uint32_t kId = msgid::kCommandAck;
  std::uint16_t command = 0;
  std::uint8_t result = mav_result::kAccepted;
  // Extensions.
  std::uint8_t progress = 0;
  std::int32_t result_param2 = 0;
  std::uint8_t target_system = 0;
  std::uint8_t target_component = 0;

  void pack(Payload& out) const;
  static CommandAck unpack(const Payload& in);
};

struct BatteryStatus {
  static constexpr std::uint32_t kId = msgid::kBatteryStatus;
  std::uint8_t id = 0;
  std::uint8_t battery_function = mav_battery_function::kUnknown;
  std::uint8_t type = mav_battery_type::kUnknown;
  std::int16_t temperature = not_provided::kTemperature;                            // cdegC
  std::array<std::uint16_t, 10> voltages = filled<10>(not_provided::kCellVoltage);  // mV
  std::int16_t current_battery = not_provided::kBatteryCurrent;                     // cA
  std::int32_t current_consumed = not_provided::kCurrentConsumed;                   // mAh
  std::int32_t energy_consumed = not_provided::kEnergyConsumed;                     // hJ
  std::int8_t battery_remaining = not_provided::kBatteryRemaining;                  // %
  // Extensions.
  std::int32_t time_remaining = not_provided::kTimeRemaining;  // s
  std::uint8_t charge_state = mav_battery_charge_state::kUndefined;
  std::array<std::uint16_t, 4> voltages_ext = filled<4>(not_provided::kCellVoltageExt);  // mV
  std::uint8_t mode = mav_battery_mode::kUnknown;
  std::uint32_t fault_bitmask = 0;

  void pack(Payload& out) const;
  static BatteryStatus unpack(const Payload& in);
};

struct Statustext {
  static constexpr std::uint32_t kId = msgid::kStatustext;
  static constexpr std::size_t kTextLength = 50;
  std::uint8_t severity = mav_severity::kInfo;
  std::string text;
  // Extensions.
  std::uint16_t id = 0;
  std::uint8_t chunk_seq = 0;

  void pack(Payload& out) const;
  static Statustext unpack(const Payload& in);
};

struct GeneratorStatus {
  static constexpr std::uint32_t kId = msgid::kGeneratorStatus;
  std::uint64_t status = 0;                                         // mav_generator_status_flag bits
  std::uint16_t generator_speed = not_provided::kGeneratorSpeed;    // rpm
  float battery_current = not_provided::kFloat;                     // A, positive out
  float load_current = not_provided::kFloat;                        // A
  float power_generated = not_provided::kFloat;                     // W
  float bus_voltage = 0.0F;                                         // V (the definition gives no "not provided" value)
  std::int16_t rectifier_temperature = not_provided::kTemperature;  // degC
  float bat_current_setpoint = not_provided::kFloat;                // A
  std::int16_t generator_temperature = not_provided::kTemperature;  // degC
  std::uint32_t runtime = not_provided::kRuntime;                   // s
  std::int32_t time_until_maintenance = not_provided::kTimeUntilMaintenance;  // s

  void pack(Payload& out) const;
  static GeneratorStatus unpack(const Payload& in);
};

struct RelayStatus {
  static constexpr std::uint32_t kId = msgid::kRelayStatus;
  std::uint32_t time_boot_ms = 0;
  std::uint16_t on = 0;
  std::uint16_t present = 0;

  void pack(Payload& out) const;
  static RelayStatus unpack(const Payload& in);
};

template <class Message>
std::optional<Message> decode(const Frame& frame) {
  if (frame.msgid != Message::kId) return std::nullopt;
  return Message::unpack(frame.payload);
}

}  // namespace pmu::mavlink
