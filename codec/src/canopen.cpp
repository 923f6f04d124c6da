#include "pmu/codec/canopen.hpp"

#include <cstdio>

#include "bytes.hpp"
#include "canopen_table.hpp"

namespace pmu::codec::canopen {
namespace {

bool is_battery_id(std::uint32_t id) noexcept {
  for (const auto cob : kBatteryCobIds)
    if (id == cob) return true;
  return false;
}

bool mppt_slot(std::uint32_t id, std::uint8_t& device, std::uint16_t& offset) noexcept {
  if (id < kMpptBase || id >= kMpptBase + kMpptStride * kMpptDevices) return false;
  device = static_cast<std::uint8_t>((id - kMpptBase) / kMpptStride);
  offset = static_cast<std::uint16_t>((id - kMpptBase) % kMpptStride);
  return offset < kMpptIdsUsed;  // the rest of each block is unassigned
}

double scalar(Type t, const std::uint8_t* p) noexcept {
  switch (t) {
    case Type::U8: return p[0];
    case Type::I8: return as_signed(p[0]);
    case Type::Bool: return p[0] != 0 ? 1 : 0;
    case Type::U16: return le16(p);
    case Type::I16: return as_signed16(le16(p));
    case Type::U32: return le32(p);
    case Type::U8x4: return p[0];
  }
  return 0;
}

}  // namespace

bool is_canopen_id(std::uint32_t id, bool extended) noexcept {
  if (extended) return false;
  std::uint8_t device = 0;
  std::uint16_t offset = 0;
  return is_battery_id(id) || mppt_slot(id, device, offset);
}

Result<CanOpenMessage, Error> decode(const CanFrame& frame) noexcept {
  Error err;
  err.cob_id = static_cast<std::uint16_t>(frame.id & 0xFFFF);
  err.length = frame.length;
  CanOpenMessage m;
  std::uint16_t offset = 0;
  const Entry* table = nullptr;
  std::size_t table_size = 0;
  if (!frame.extended && is_battery_id(frame.id)) {
    m.source = Source::Battery;
    table = kBattery;
    table_size = std::size(kBattery);
    offset = static_cast<std::uint16_t>(frame.id);
  } else if (!frame.extended && mppt_slot(frame.id, m.device, offset)) {
    m.source = Source::Mppt;
    table = kMppt;
    table_size = std::size(kMppt);
  } else {
    err.kind = ErrorKind::NotOurs;
    return Unexpected{err};
  }
  m.cob_id = static_cast<std::uint16_t>(frame.id);
  if (frame.remote) {
    err.kind = ErrorKind::RemoteFrame;
    return Unexpected{err};
  }
  const std::uint8_t len = frame.length > kMaxDataLength ? kMaxDataLength : frame.length;
  if (len < kHeader + 1) {
    err.kind = ErrorKind::TooShort;
    err.needed = kHeader + 1;
    return Unexpected{err};
  }
  const std::uint8_t* d = frame.data.data();
  m.command_byte = d[0];
  m.index = le16(d + 1);
  m.subindex = d[3];
  err.index = m.index;
  err.subindex = m.subindex;

  const Entry* hit = nullptr;
  bool index_seen = false;
  for (std::size_t i = 0; i < table_size; ++i) {
    const Entry& e = table[i];
    if (e.cob_offset != offset) continue;
    if (e.index != kAnyIndex && e.index != m.index) continue;
    index_seen = true;
    if (e.subindex != kAnySubindex && e.subindex != m.subindex) continue;
    hit = &e;
    break;
  }
  if (!hit) {
    err.kind = index_seen ? ErrorKind::UnknownSubindex : ErrorKind::UnknownIndex;
    return Unexpected{err};
  }
  const std::uint8_t need = static_cast<std::uint8_t>(kHeader + size_of(hit->type));
  if (len < need) {
    err.kind = ErrorKind::TooShort;
    err.needed = need;
    return Unexpected{err};
  }
  const std::uint8_t* v = d + kHeader;
  if (frame.id == 0x482) m.fields[m.field_count++] = Field{"cell", static_cast<double>(m.subindex), ""};
  if (hit->type == Type::U8x4) {
    // Four values, one per byte; the names are fixed so no string is built at run time.
    static constexpr std::string_view kTemps[4] = {"temperature_1", "temperature_2", "temperature_3", "temperature_4"};
    static constexpr std::string_view kChannels[4] = {"channel_1_active", "channel_2_active", "channel_3_active",
                                                      "channel_4_active"};
    const auto* names = hit->name == "temperature_collection" ? kTemps : kChannels;
    for (std::size_t i = 0; i < 4; ++i) m.fields[i] = Field{names[i], static_cast<double>(v[i]), hit->unit};
    m.field_count = 4;
  } else {
    m.fields[m.field_count++] = Field{hit->name, scalar(hit->type, v) / hit->divisor, hit->unit};
  }
  return m;
}

std::string Error::describe() const {
  char buf[160];
  switch (kind) {
    case ErrorKind::NotOurs: std::snprintf(buf, sizeof buf, "id %03X is not a battery or MPPT frame", cob_id); break;
    case ErrorKind::TooShort:
      std::snprintf(buf, sizeof buf, "CANopen frame %03X too short: length %u, needs %u", cob_id, length, needed);
      break;
    case ErrorKind::UnknownIndex:
      std::snprintf(buf, sizeof buf, "CANopen frame %03X: unknown index 0x%04X", cob_id, index);
      break;
    case ErrorKind::UnknownSubindex:
      std::snprintf(buf, sizeof buf, "CANopen frame %03X: unknown subindex 0x%02X of index 0x%04X", cob_id, subindex,
                    index);
      break;
    case ErrorKind::RemoteFrame: std::snprintf(buf, sizeof buf, "remote frame %03X carries no data", cob_id); break;
  }
  return buf;
}

}  // namespace pmu::codec::canopen
