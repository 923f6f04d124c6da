// libFuzzer target: arbitrary bytes -> CAN frames -> pmu::codec::decode (with and without a
// firmware version) and canopen::decode. The decoders must be total: no crash, no sanitizer
// report, and every outcome consistent with the frame it came from (checked below; a broken
// invariant traps, which libFuzzer reports as a crash with the input that caused it).
//
// Input: a sequence of 16-byte records, one frame each; a short last record is zero-padded.
//   [0..3]  identifier, little-endian, all 32 bits (ids above 29 bits reach the decoders too)
//   [4]     bit 0 extended, bit 1 remote, bit 2 firmware known
//   [5]     length code, low 4 bits: 0..15 (above 8 is malformed)
//   [6..13] the 8 data bytes (bytes past the length code are filler the decoders must ignore)
//   [14,15] firmware major, minor (used when bit 2 of [4] is set)
#include <cstddef>
#include <cstdint>
#include <optional>
#include <variant>

#include "pmu/codec/canopen.hpp"
#include "pmu/codec/decode.hpp"
#include "pmu/codec/encode.hpp"

namespace {

using namespace pmu::codec;  // NOLINT: a fuzz target, not a header

constexpr std::size_t kRecord = 16;

void require(bool ok) {
  if (!ok) __builtin_trap();
}

CanFrame flip_tail(CanFrame f) {
  for (std::size_t i = f.length; i < kMaxDataLength; ++i) f.data[i] = static_cast<std::uint8_t>(~f.data[i]);
  return f;
}

// Payloads that carry every bit of the frame must re-encode to the same frame.
void check_reencode(const CanFrame& f, const PmuMessage& m) {
  std::optional<Encoded> again;
  if (const auto* e = std::get_if<BatteryEnergy>(&m.payload)) again = encode_battery_energy(*e, m.address);
  if (const auto* s = std::get_if<SerialNumber>(&m.payload)) again = encode_serial(s->serial_number, m.address);
  if (const auto* fi = std::get_if<FirmwareInfo>(&m.payload)) again = encode_firmware(*fi, m.address);
  if (const auto* p = std::get_if<ParameterValue>(&m.payload))
    again = encode_parameter_reply(p->parameter, p->raw, m.address);
  if (!again) return;
  require(again->ok());
  require(again->value() == f);
}

void check_pmu(const CanFrame& f, std::optional<FirmwareVersion> fw) {
  const auto r = decode(f, fw);
  require(r.ok() == static_cast<bool>(r));
  if (r.ok()) {
    const PmuMessage& m = r.value();
    require(f.extended && !f.remote && f.length <= kMaxDataLength);
    require(f.id <= kMaxExtendedId && (f.id >> 24) == kGroupId);
    require(m.address == (f.id & 0xFFFFu));
    require(static_cast<std::uint32_t>(m.packet) == ((f.id >> 16) & 0xFFu));
    require(is_known_packet(static_cast<std::uint8_t>(m.packet)));
    require(m.request == (f.length == 0));
    require(m.request || f.length == data_length(m.packet));
    require(!m.request || std::holds_alternative<NoPayload>(m.payload));
    require(!m.unsupported_by_firmware || m.packet == PacketId::MeasurementRequest);
    check_reencode(f, m);
  } else {
    const DecodeError& e = r.error();
    require(e.id == f.id && e.length == f.length);
    require(!e.describe().empty());
    switch (e.kind) {
      case DecodeErrorKind::NotOurs: require(!f.extended || f.id > kMaxExtendedId || (f.id >> 24) != kGroupId); break;
      case DecodeErrorKind::UnknownPacket: require(!is_known_packet(e.packet)); break;
      case DecodeErrorKind::RemoteFrame: require(f.remote); break;
      case DecodeErrorKind::BadLength: require(f.length > kMaxDataLength); break;
      case DecodeErrorKind::WrongLength: require(f.length <= kMaxDataLength); break;
    }
  }
  // Only the bytes the frame carries may matter.
  const auto r2 = decode(flip_tail(f), fw);
  require(r2.ok() == r.ok());
  if (!r.ok()) require(r2.error().kind == r.error().kind);
}

void check_canopen(const CanFrame& f) {
  const auto r = canopen::decode(f);
  require(r.ok() == static_cast<bool>(r));
  if (r.ok()) {
    const canopen::CanOpenMessage& m = r.value();
    require(!f.extended && !f.remote && canopen::is_canopen_id(f.id, false));
    require(m.cob_id == f.id && f.length >= 5);
    require(m.field_count >= 1 && m.field_count <= 4);
    require(m.command_byte == f.data[0]);
    require(m.device < 8);
  } else {
    const canopen::Error& e = r.error();
    require(!e.describe().empty());
    if (!canopen::is_canopen_id(f.id, f.extended)) require(e.kind == canopen::ErrorKind::NotOurs);
  }
  if (f.length <= kMaxDataLength) {
    const auto r2 = canopen::decode(flip_tail(f));
    require(r2.ok() == r.ok());
    if (!r.ok()) require(r2.error().kind == r.error().kind);
  }
}

void run_record(const std::uint8_t (&rec)[kRecord]) {
  CanFrame f;
  f.id = std::uint32_t{rec[0]} | (std::uint32_t{rec[1]} << 8) | (std::uint32_t{rec[2]} << 16) |
         (std::uint32_t{rec[3]} << 24);
  f.extended = (rec[4] & 1u) != 0;
  f.remote = (rec[4] & 2u) != 0;
  f.length = static_cast<std::uint8_t>(rec[5] & 0x0Fu);
  for (std::size_t i = 0; i < kMaxDataLength; ++i) f.data[i] = rec[6 + i];
  check_pmu(f, std::nullopt);
  if ((rec[4] & 4u) != 0) check_pmu(f, FirmwareVersion{rec[14], rec[15]});
  check_canopen(f);
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  for (std::size_t at = 0; at < size; at += kRecord) {
    std::uint8_t rec[kRecord] = {};
    for (std::size_t i = 0; i < kRecord && at + i < size; ++i) rec[i] = data[at + i];
    run_record(rec);
  }
  return 0;
}
