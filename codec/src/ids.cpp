#include "pmu/codec/ids.hpp"

#include "pmu/codec/packets.hpp"

namespace pmu::codec {

bool is_known_packet(std::uint8_t packet) noexcept { return find_packet(static_cast<PacketId>(packet)) != nullptr; }

std::string_view packet_name(PacketId packet) noexcept {
  const PacketSpec* p = find_packet(packet);
  return p ? p->name : "unknown";
}

std::optional<PacketId> packet_from_name(std::string_view name) noexcept {
  for (const auto& p : kPacketTable)
    if (p.name == name) return p.id;
  return std::nullopt;
}

IdParse parse_id(std::uint32_t id, bool extended) noexcept {
  IdParse r;
  if (!extended || id > 0x1FFFFFFFu) {
    r.error = IdError::NotExtended;
    return r;
  }
  if ((id >> 24) != kGroupId) {
    r.error = IdError::ForeignGroup;
    return r;
  }
  r.raw_packet = static_cast<std::uint8_t>((id >> 16) & 0xFFu);
  if (!is_known_packet(r.raw_packet)) {
    r.error = IdError::UnknownPacket;
    return r;
  }
  r.id = PmuId{static_cast<PacketId>(r.raw_packet), address_of_id(id)};
  return r;
}

}  // namespace pmu::codec
