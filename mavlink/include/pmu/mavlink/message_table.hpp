#pragma once
// The messages this library knows: id, CRC_EXTRA and payload lengths, from the definitions
// in mavlink/mavlink's message_definitions/v1.0 (minimal.xml, common.xml; the commit is in
// mavlink/README.md). The parser checks a frame's CRC only for these: a frame of any other id
// cannot be checked and is counted, not delivered.
//
// CRC_EXTRA is the X.25 CRC of "NAME " and, for each field before <extensions/> in wire
// order, "type name " (the C type without "_mavlink_version", "char" for char[n]) and, for an
// array, its length as one byte; the top and bottom bytes of that CRC XORed together.
// Wire order: fields sorted by the size of their (element) type, largest first, stable;
// extension fields follow in declaration order. min_length is the payload of the fields
// before <extensions/>, max_length that with the extensions.

#include <array>
#include <cstdint>
#include <string_view>

namespace pmu::mavlink {

struct MessageInfo {
  std::uint32_t id;
  std::string_view name;
  std::uint8_t crc_extra;
  std::uint8_t min_length;
  std::uint8_t max_length;
};

namespace msgid {
inline constexpr std::uint32_t kHeartbeat = 0;
inline constexpr std::uint32_t kParamRequestRead = 20;
inline constexpr std::uint32_t kParamRequestList = 21;
inline constexpr std::uint32_t kParamValue = 22;
inline constexpr std::uint32_t kParamSet = 23;
inline constexpr std::uint32_t kCommandLong = 76;
inline constexpr std::uint32_t kCommandAck = 77;
inline constexpr std::uint32_t kBatteryStatus = 147;
inline constexpr std::uint32_t kStatustext = 253;
inline constexpr std::uint32_t kGeneratorStatus = 373;
inline constexpr std::uint32_t kRelayStatus = 376;
}  // namespace msgid

inline constexpr std::array<MessageInfo, 11> kMessageTable{{
    {msgid::kHeartbeat, "HEARTBEAT", 50, 9, 9},
    {msgid::kParamRequestRead, "PARAM_REQUEST_READ", 214, 20, 20},
    {msgid::kParamRequestList, "PARAM_REQUEST_LIST", 159, 2, 2},
    {msgid::kParamValue, "PARAM_VALUE", 220, 25, 25},
    {msgid::kParamSet, "PARAM_SET", 168, 23, 23},
    {msgid::kCommandLong, "COMMAND_LONG", 152, 33, 33},
    {msgid::kCommandAck, "COMMAND_ACK", 143, 3, 10},
    {msgid::kBatteryStatus, "BATTERY_STATUS", 154, 36, 54},
    {msgid::kStatustext, "STATUSTEXT", 83, 51, 54},
    {msgid::kGeneratorStatus, "GENERATOR_STATUS", 117, 42, 42},
    {msgid::kRelayStatus, "RELAY_STATUS", 199, 8, 8},
}};

// The row of a message id, or nullptr for an id this library does not know.
constexpr const MessageInfo* find_message(std::uint32_t id) noexcept {
  for (const auto& info : kMessageTable) {
    if (info.id == id) return &info;
  }
  return nullptr;
}

}  // namespace pmu::mavlink
