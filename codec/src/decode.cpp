#include "pmu/codec/decode.hpp"

#include <cstdio>
#include <type_traits>
#include <utility>

#include "bytes.hpp"
#include "fields.hpp"
#include "pmu/codec/packets.hpp"

namespace pmu::codec {
namespace {

// One field of a telemetry packet, its row a compile-time constant so the wire type and
// the member fold into straight-line code (no per-field dispatch on the frame path).
template <class Packet, std::size_t I>
void decode_field(Packet& p, const std::uint8_t* d, bool external) noexcept {
  constexpr const auto& f = Telemetry<Packet>::fields[I];
  using Value = std::remove_reference_t<decltype(p.*f.member)>;
  if constexpr (f.external_sensor) {
    // Left at "no sensor" (the struct's NaN) before 1.12: the feature did not exist, so the
    // byte means nothing.
    if (!external) return;
  }
  const std::int32_t raw = read_field(f.wire, d + f.offset);
  if constexpr (std::is_floating_point_v<Value>) {
    if constexpr (f.no_sensor) {
      if (raw == kNoSensorRaw) {
        p.*f.member = kNoSensor;
        return;
      }
    }
    // Division (not multiplication by 0.1) so 123 -> 12.3 exactly as printed.
    p.*f.member = static_cast<double>(raw) / f.divisor;
  } else {
    p.*f.member = static_cast<Value>(raw);
  }
}

template <class Packet, std::size_t... I>
Packet decode_fields(const std::uint8_t* d, std::optional<FirmwareVersion> fw, std::index_sequence<I...>) noexcept {
  Packet p;
  bool external = true;
  if constexpr ((Telemetry<Packet>::fields[I].external_sensor || ...))
    external = supports(fw, Feature::ExternalTemperatures);
  (decode_field<Packet, I>(p, d, external), ...);
  return p;
}

// One telemetry packet from its table (telemetry.hpp).
template <class Packet>
Packet decode_fields(const std::uint8_t* d, std::optional<FirmwareVersion> fw) noexcept {
  return decode_fields<Packet>(d, fw, std::make_index_sequence<Telemetry<Packet>::fields.size()>{});
}

Status decode_status(const std::uint8_t* d, std::optional<FirmwareVersion> fw) noexcept {
  Status s;
  s.generator_rpm = be16(d);
  const std::uint8_t f0 = d[2], f1 = d[3], f2 = d[4];
  s.generation_enabled = f0 & 0x10;
  s.thermal_shutdown = f0 & 0x20;
  s.interpretation = interpret_flags(fw);
  if (s.interpretation.bit6 == Bit6Meaning::SoaShutdown)
    s.soa_shutdown = f0 & 0x40;
  else
    s.start_button = f0 & 0x40;
  s.payload_shed = f0 & 0x80;
  s.starter_ready = supports(fw, Feature::StarterReadyFlag) && (f1 & 0x80);
  s.outputs = f2 & output_bit::All;
  return s;
}

Payload decode_payload(PacketId p, const std::uint8_t* d, std::optional<FirmwareVersion> fw) noexcept {
  switch (p) {
    case PacketId::Voltages: return decode_fields<Voltages>(d, fw);
    case PacketId::Currents: return decode_fields<Currents>(d, fw);
    case PacketId::BatteryEnergy: return decode_fields<BatteryEnergy>(d, fw);
    case PacketId::Temperatures: return decode_fields<Temperatures>(d, fw);
    case PacketId::Status: return decode_status(d, fw);
    case PacketId::MeasurementRequest:
      // Bits 5..7 are "don't care" (table 7).
      return MeasurementRequest{static_cast<std::uint8_t>(d[0] & group_bit::All)};
    case PacketId::Outputs: return OutputStates{static_cast<std::uint8_t>(d[0] & output_bit::All)};
    case PacketId::EnableOutputs: return EnableOutputs{static_cast<std::uint8_t>(d[0] & output_bit::All)};
    case PacketId::DisableOutputs: return DisableOutputs{static_cast<std::uint8_t>(d[0] & output_bit::All)};
    case PacketId::Generation: return GenerationState{(d[0] & 0x01) != 0};
    case PacketId::Serial: return SerialNumber{be16(d)};
    case PacketId::Firmware: return FirmwareInfo{d[0], d[1], d[2], d[3], be16(d + 4)};
    case PacketId::EngineStart:
    case PacketId::EngineStop:
    case PacketId::Reset: return NoPayload{};
    case PacketId::AvionicsVoltage:
    case PacketId::PayloadVoltage:
    case PacketId::ServoVoltage:
    case PacketId::BatteryVoltage:
    case PacketId::PacketPeriod:
    case PacketId::PacketsStreamed:
    case PacketId::TemperatureOffset:
    case PacketId::UpperTemperatureLimit:
    case PacketId::PowerUpState:
    case PacketId::CrankingTime:
    case PacketId::CanAddress: break;  // a stored parameter: its width comes from the spec table below
  }
  if (auto param = parameter_from_packet(p)) {
    const auto& spec = spec_of(*param);
    const std::uint32_t raw = spec.width == 2 ? be16(d) : d[0];
    return ParameterValue{*param, raw, parameter_value(*param, raw)};
  }
  return NoPayload{};
}

}  // namespace

std::uint8_t data_length(PacketId packet) noexcept {
  const PacketSpec* p = find_packet(packet);
  return p ? p->length : 0;
}

bool has_zero_length_get(PacketId packet) noexcept {
  const PacketSpec* p = find_packet(packet);
  return p && p->zero_length_get;
}

Result<PmuMessage, DecodeError> decode(const CanFrame& frame, std::optional<FirmwareVersion> fw) noexcept {
  DecodeError err;
  err.id = frame.id;
  err.length = frame.length;

  const IdParse id = parse_id(frame.id, frame.extended);
  if (!id.id) {
    err.kind = id.error == IdError::UnknownPacket ? DecodeErrorKind::UnknownPacket : DecodeErrorKind::NotOurs;
    err.packet = id.raw_packet;
    return Unexpected{err};
  }
  return decode(frame, *id.id, fw);
}

Result<PmuMessage, DecodeError> decode(const CanFrame& frame, const PmuId& id,
                                       std::optional<FirmwareVersion> fw) noexcept {
  DecodeError err;
  err.id = frame.id;
  err.length = frame.length;
  const PacketId packet = id.packet;
  err.packet = static_cast<std::uint8_t>(packet);
  if (frame.remote) {
    err.kind = DecodeErrorKind::RemoteFrame;
    return Unexpected{err};
  }
  if (frame.length > kMaxDataLength) {
    err.kind = DecodeErrorKind::BadLength;
    return Unexpected{err};
  }

  PmuMessage msg;
  msg.packet = packet;
  msg.address = id.address;
  msg.unsupported_by_firmware = packet == PacketId::MeasurementRequest && !supports(fw, Feature::MeasurementRequest);

  const std::uint8_t want = data_length(packet);
  if (frame.length == 0 && (want == 0 || has_zero_length_get(packet))) {
    msg.request = true;
    msg.payload = NoPayload{};
    return msg;
  }
  if (want == 0 || frame.length != want) {
    err.kind = DecodeErrorKind::WrongLength;
    err.expected = want;
    return Unexpected{err};
  }
  msg.payload = decode_payload(packet, frame.data.data(), fw);
  return msg;
}

std::string DecodeError::describe() const {
  char buf[160];
  const auto name = is_known_packet(packet) ? packet_name(static_cast<PacketId>(packet)) : std::string_view{};
  switch (kind) {
    case DecodeErrorKind::NotOurs:
      std::snprintf(buf, sizeof buf, "id %X is not a PMU frame (needs a 29-bit id in group 0x1E)", id);
      break;
    case DecodeErrorKind::UnknownPacket:
      std::snprintf(buf, sizeof buf, "unknown packet 0x%02X in id %08X", packet, id);
      break;
    case DecodeErrorKind::RemoteFrame:
      std::snprintf(buf, sizeof buf, "remote frame for packet 0x%02X %.*s (the PMU uses data frames only)", packet,
                    static_cast<int>(name.size()), name.data());
      break;
    case DecodeErrorKind::BadLength: std::snprintf(buf, sizeof buf, "length %u exceeds 8 bytes", length); break;
    case DecodeErrorKind::WrongLength: {
      const auto p = static_cast<PacketId>(packet);
      const char* get = has_zero_length_get(p) ? ", or 0 for a get" : "";
      std::snprintf(buf, sizeof buf, "wrong length %u for packet 0x%02X %.*s (expects %u%s)", length, packet,
                    static_cast<int>(name.size()), name.data(), expected, get);
      break;
    }
  }
  return buf;
}

}  // namespace pmu::codec
