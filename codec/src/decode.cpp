#include "pmu/codec/decode.hpp"

#include <cstdio>

#include "bytes.hpp"

namespace pmu::codec {
namespace {

constexpr std::int8_t kNoSensorRaw = -128;

double temperature(std::uint8_t byte, bool sensor_optional) noexcept {
  const auto t = as_signed(byte);
  if (sensor_optional && t == kNoSensorRaw) return kNoSensor;
  return t;
}

Voltages decode_voltages(const std::uint8_t* d) noexcept {
  // Table 2: x10 except 28 V (x5) and generator (x2.5).
  return {d[0] / 10.0, d[1] / 5.0, d[2] / 10.0, d[3] / 10.0, d[4] / 10.0, d[5] / 10.0, d[6] / 2.5};
}

Currents decode_currents(const std::uint8_t* d) noexcept {
  // Table 3: 28 V and battery currents are signed, the outputs unsigned; all x10.
  return {d[0] / 10.0, as_signed(d[1]) / 10.0, d[2] / 10.0, d[3] / 10.0, as_signed(d[4]) / 10.0,
          as_signed(d[5]) / 10.0};
}

Temperatures decode_temperatures(const std::uint8_t* d, std::optional<FirmwareVersion> fw) noexcept {
  Temperatures t;
  t.internal = temperature(d[0], false);
  t.starter = temperature(d[4], false);
  // External sensing exists from firmware 1.12; earlier firmware has nothing to report.
  if (supports(fw, Feature::ExternalTemperatures)) {
    t.battery_a = temperature(d[1], true);
    t.battery_b = temperature(d[2], true);
    t.generator = temperature(d[3], true);
  }
  return t;
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
    case PacketId::Voltages: return decode_voltages(d);
    case PacketId::Currents: return decode_currents(d);
    case PacketId::BatteryEnergy:
      return BatteryEnergy{as_signed16(be16(d)), as_signed16(be16(d + 2))};
    case PacketId::Temperatures: return decode_temperatures(d, fw);
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
  switch (packet) {
    case PacketId::Voltages: return 7;
    case PacketId::Currents: return 6;
    case PacketId::BatteryEnergy: return 4;
    case PacketId::Temperatures: return 5;
    case PacketId::Status: return 5;
    case PacketId::CanAddress: return 2;
    case PacketId::EngineStart:
    case PacketId::EngineStop:
    case PacketId::Reset: return 0;
    case PacketId::Serial: return 2;
    case PacketId::Firmware: return 6;
    case PacketId::MeasurementRequest:
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
    case PacketId::Outputs:
    case PacketId::EnableOutputs:
    case PacketId::DisableOutputs:
    case PacketId::Generation: return 1;
  }
  return 1;  // an id outside table 1 (a PacketId made from a raw byte)
}

bool has_zero_length_get(PacketId packet) noexcept {
  const auto id = static_cast<std::uint8_t>(packet);
  return id <= 0x20 || packet == PacketId::Generation || packet == PacketId::Serial ||
         packet == PacketId::Firmware;
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
  msg.unsupported_by_firmware =
      packet == PacketId::MeasurementRequest && !supports(fw, Feature::MeasurementRequest);

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
      std::snprintf(buf, sizeof buf, "remote frame for packet 0x%02X %.*s (the PMU uses data frames only)",
                    packet, static_cast<int>(name.size()), name.data());
      break;
    case DecodeErrorKind::BadLength:
      std::snprintf(buf, sizeof buf, "length %u exceeds 8 bytes", length);
      break;
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
