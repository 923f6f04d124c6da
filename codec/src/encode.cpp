#include "pmu/codec/encode.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <type_traits>
#include <utility>

#include "bytes.hpp"
#include "fields.hpp"
#include "pmu/codec/decode.hpp"

namespace pmu::codec {
namespace {

// Tolerance for "on a step": DDS carries float32, so 12.3f arrives as 12.300000190734863.
constexpr double kStepTolerance = 1e-3;

CanFrame frame(PacketId p, std::uint16_t address, std::uint8_t length) noexcept {
  CanFrame f;
  f.id = make_id(p, address);
  f.extended = true;
  f.length = length;
  return f;
}

Encoded one_byte(PacketId p, std::uint16_t address, std::uint8_t value) noexcept {
  CanFrame f = frame(p, address, 1);
  f.data[0] = value;
  return f;
}

EncodeError error(EncodeErrorKind kind, std::string_view field, double value) noexcept {
  EncodeError e;
  e.kind = kind;
  e.field = field;
  e.value = value;
  return e;
}

// A measured value in [min, max] rounded to its resolution `1/divisor`. Used for telemetry,
// where any real reading is legitimate but must fit the field.
Result<long, EncodeError> measured(double value, double divisor, long raw_min, long raw_max, std::string_view field,
                                   std::string_view unit) noexcept {
  if (!std::isfinite(value)) return Unexpected{error(EncodeErrorKind::NotANumber, field, value)};
  const double x = value * divisor;
  if (x < static_cast<double>(raw_min) - 0.5 || x > static_cast<double>(raw_max) + 0.5) {
    EncodeError e = error(EncodeErrorKind::OutOfRange, field, value);
    e.unit = unit;
    e.min = static_cast<double>(raw_min) / divisor;
    e.max = static_cast<double>(raw_max) / divisor;
    return Unexpected{e};
  }
  long raw = std::lround(x);
  if (raw < raw_min) raw = raw_min;
  if (raw > raw_max) raw = raw_max;
  return raw;
}

// One field of a telemetry packet into `out`, its row a compile-time constant (as in
// decode.cpp); false with `error` set when the value does not fit the field.
template <class Packet, std::size_t I>
bool encode_field(const Packet& p, CanFrame& out, EncodeError& error) noexcept {
  constexpr const auto& f = Telemetry<Packet>::fields[I];
  const auto value = p.*f.member;
  long raw = 0;
  if constexpr (std::is_floating_point_v<decltype(value)>) {
    if (f.no_sensor && std::isnan(value)) {
      raw = kNoSensorRaw;
    } else {
      // The in-range test inline, measured() only to word a refusal: returning its Result
      // for every field made the table-driven encoder a third slower than the code it
      // replaced. The test is measured()'s own, so both agree on every value.
      const double x = value * f.divisor;
      if (std::isfinite(x) && x >= f.raw_min - 0.5 && x <= f.raw_max + 0.5) {
        raw = std::clamp(std::lround(x), static_cast<long>(f.raw_min), static_cast<long>(f.raw_max));
      } else {
        error = measured(value, f.divisor, f.raw_min, f.raw_max, f.name, f.unit).error();
        return false;
      }
    }
  } else {
    raw = value;  // an integer field holds nothing its wire type cannot carry
  }
  write_field(f.wire, out.data.data() + f.offset, raw);
  return true;
}

// One telemetry packet from its table (telemetry.hpp); the first field that does not fit
// is the error.
template <class Packet, std::size_t... I>
Encoded encode_fields(const Packet& p, std::uint16_t address, std::index_sequence<I...>) noexcept {
  constexpr PacketId id = Telemetry<Packet>::packet;
  CanFrame f = frame(id, address, data_length(id));
  EncodeError error;
  if (!(encode_field<Packet, I>(p, f, error) && ...)) return Unexpected{error};
  return f;
}

template <class Packet>
Encoded encode_fields(const Packet& p, std::uint16_t address) noexcept {
  return encode_fields(p, address, std::make_index_sequence<Telemetry<Packet>::fields.size()>{});
}

Encoded mask_command(PacketId p, std::uint8_t mask, std::uint16_t address, bool allow_empty) noexcept {
  const auto name = packet_name(p);
  if (mask & ~output_bit::All) {
    EncodeError e = error(EncodeErrorKind::InvalidBits, name, mask);
    e.bits = output_bit::All;
    return Unexpected{e};
  }
  if (!allow_empty && mask == 0) return Unexpected{error(EncodeErrorKind::EmptyMask, name, 0)};
  return one_byte(p, address, mask);
}

std::string number(double v, int decimals) {
  char buf[48];
  std::snprintf(buf, sizeof buf, "%.*f", decimals, v);
  if (std::strtod(buf, nullptr) != v) std::snprintf(buf, sizeof buf, "%.10g", v);
  return buf;
}

}  // namespace

// ---- master side -------------------------------------------------------------------------

Encoded encode_get(PacketId packet, std::uint16_t address) noexcept {
  if (!has_zero_length_get(packet)) return Unexpected{error(EncodeErrorKind::NotAGet, packet_name(packet), 0)};
  return frame(packet, address, 0);
}

Result<std::uint32_t, EncodeError> to_raw(Parameter p, double value, std::optional<FirmwareVersion> fw) noexcept {
  const ParameterSpec& s = spec_of(p);
  if (!std::isfinite(value)) return Unexpected{error(EncodeErrorKind::NotANumber, s.name, value)};
  const double x = value * s.divisor;
  const double lo = static_cast<double>(s.raw_min), hi = static_cast<double>(s.raw_max);
  if (s.kind == ParameterKind::Mask) {
    const double r = std::round(x);
    if (std::fabs(x - r) > kStepTolerance || r < 0 || r > 255) {
      // Said as the mask the spec defines (0..0x1F for PS), not the byte's 0..255.
      EncodeError e = error(EncodeErrorKind::InvalidBits, s.name, value);
      e.bits = s.raw_max;
      return Unexpected{e};
    }
    const auto raw = static_cast<std::uint32_t>(r);
    if (raw & ~s.raw_max) {
      EncodeError e = error(EncodeErrorKind::InvalidBits, s.name, value);
      e.bits = s.raw_max;
      return Unexpected{e};
    }
    if (p == Parameter::PowerUpState) {
      const std::uint8_t allowed = power_up_state_mask(fw);
      if (raw & ~std::uint32_t{allowed}) {
        EncodeError e = error(EncodeErrorKind::Unsupported, s.name, value);
        e.bits = allowed;
        e.firmware = fw;
        e.needs = (raw & power_up_bit::SoaManagement) && !(allowed & power_up_bit::SoaManagement)
                      ? first_firmware_with(Feature::SoaManagement)
                      : first_firmware_with(Feature::BatteryDisconnectDetect);
        return Unexpected{e};
      }
    }
    return raw;
  }
  if (x < lo - kStepTolerance || x > hi + kStepTolerance) {
    EncodeError e = error(EncodeErrorKind::OutOfRange, s.name, value);
    e.unit = s.unit;
    e.min = lo / s.divisor;
    e.max = hi / s.divisor;
    return Unexpected{e};
  }
  const double r = std::round(x);
  if (std::fabs(x - r) > kStepTolerance) {
    EncodeError e = error(EncodeErrorKind::NotOnStep, s.name, value);
    e.unit = s.unit;
    e.min = 1.0 / s.divisor;  // the step
    return Unexpected{e};
  }
  return static_cast<std::uint32_t>(r);
}

Encoded encode_set(Parameter p, double value, std::uint16_t address, std::optional<FirmwareVersion> fw) noexcept {
  auto raw = to_raw(p, value, fw);
  if (!raw) return Unexpected{raw.error()};
  return encode_parameter_reply(p, *raw, address);
}

Encoded encode_measurement_request(std::uint8_t groups, std::uint16_t address,
                                   std::optional<FirmwareVersion> fw) noexcept {
  const auto name = packet_name(PacketId::MeasurementRequest);
  if (!supports(fw, Feature::MeasurementRequest)) {
    EncodeError e = error(EncodeErrorKind::Unsupported, name, groups);
    e.firmware = fw;
    e.needs = first_firmware_with(Feature::MeasurementRequest);
    return Unexpected{e};
  }
  if (groups & ~group_bit::All) {
    EncodeError e = error(EncodeErrorKind::InvalidBits, name, groups);
    e.bits = group_bit::All;
    return Unexpected{e};
  }
  if (groups == 0) return Unexpected{error(EncodeErrorKind::EmptyMask, name, 0)};
  return one_byte(PacketId::MeasurementRequest, address, groups);
}

Encoded encode_set_outputs(std::uint8_t mask, std::uint16_t address) noexcept {
  return mask_command(PacketId::Outputs, mask, address, true);
}
Encoded encode_enable_outputs(std::uint8_t mask, std::uint16_t address) noexcept {
  return mask_command(PacketId::EnableOutputs, mask, address, false);
}
Encoded encode_disable_outputs(std::uint8_t mask, std::uint16_t address) noexcept {
  return mask_command(PacketId::DisableOutputs, mask, address, false);
}
Encoded encode_generation(bool enabled, std::uint16_t address) noexcept {
  return one_byte(PacketId::Generation, address, enabled ? 1 : 0);
}
Encoded encode_engine_start(std::uint16_t address) noexcept { return frame(PacketId::EngineStart, address, 0); }
Encoded encode_engine_stop(std::uint16_t address) noexcept { return frame(PacketId::EngineStop, address, 0); }
Encoded encode_reset(std::uint16_t address) noexcept { return frame(PacketId::Reset, address, 0); }

// ---- device side -------------------------------------------------------------------------

Encoded encode_voltages(const Voltages& v, std::uint16_t address) noexcept { return encode_fields(v, address); }
Encoded encode_currents(const Currents& c, std::uint16_t address) noexcept { return encode_fields(c, address); }
Encoded encode_battery_energy(const BatteryEnergy& e, std::uint16_t address) noexcept {
  return encode_fields(e, address);
}
Encoded encode_temperatures(const Temperatures& t, std::uint16_t address) noexcept { return encode_fields(t, address); }

Encoded encode_status(const Status& s, std::uint16_t address, std::optional<FirmwareVersion> fw) noexcept {
  if (s.outputs & ~output_bit::All) {
    EncodeError e = error(EncodeErrorKind::InvalidBits, "outputs", s.outputs);
    e.bits = output_bit::All;
    return Unexpected{e};
  }
  CanFrame f = frame(PacketId::Status, address, 5);
  put_be16(f.data.data(), s.generator_rpm);
  const bool bit6 = interpret_flags(fw).bit6 == Bit6Meaning::SoaShutdown ? s.soa_shutdown : s.start_button;
  f.data[2] = static_cast<std::uint8_t>((s.generation_enabled ? 0x10 : 0) | (s.thermal_shutdown ? 0x20 : 0) |
                                        (bit6 ? 0x40 : 0) | (s.payload_shed ? 0x80 : 0));
  f.data[3] = (s.starter_ready && supports(fw, Feature::StarterReadyFlag)) ? 0x80 : 0;
  f.data[4] = s.outputs;
  return f;
}

Encoded encode_parameter_reply(Parameter p, std::uint32_t raw, std::uint16_t address) noexcept {
  const ParameterSpec& s = spec_of(p);
  const std::uint32_t limit = s.width == 2 ? 0xFFFFu : 0xFFu;
  if (raw > limit) {
    EncodeError e = error(EncodeErrorKind::OutOfRange, s.name, raw);
    e.max = limit;
    return Unexpected{e};
  }
  CanFrame f = frame(s.packet, address, s.width);
  if (s.width == 2)
    put_be16(f.data.data(), static_cast<std::uint16_t>(raw));
  else
    f.data[0] = static_cast<std::uint8_t>(raw);
  return f;
}

Encoded encode_outputs_reply(std::uint8_t mask, std::uint16_t address) noexcept {
  return mask_command(PacketId::Outputs, mask, address, true);
}
Encoded encode_generation_reply(bool enabled, std::uint16_t address) noexcept {
  return encode_generation(enabled, address);
}
Encoded encode_serial(std::uint16_t serial, std::uint16_t address) noexcept {
  CanFrame f = frame(PacketId::Serial, address, 2);
  put_be16(f.data.data(), serial);
  return f;
}
Encoded encode_firmware(const FirmwareInfo& fi, std::uint16_t address) noexcept {
  CanFrame f = frame(PacketId::Firmware, address, 6);
  f.data[0] = fi.firmware_major;
  f.data[1] = fi.firmware_minor;
  f.data[2] = fi.build_day;
  f.data[3] = fi.build_month;
  put_be16(f.data.data() + 4, fi.build_year);
  return f;
}

// ---- messages ----------------------------------------------------------------------------

std::string EncodeError::describe() const {
  const std::string f(field);
  const std::string u = unit.empty() ? "" : " " + std::string(unit);
  const int decimals = (unit == "V" || unit == "s" || unit == "A") ? 1 : 0;
  char hex[32];
  switch (kind) {
    case EncodeErrorKind::NotANumber: return f + ": value " + number(value, 0) + " is not a number";
    case EncodeErrorKind::OutOfRange:
      return "value " + number(value, decimals) + u + " out of range " + number(min, decimals) + ".." +
             number(max, decimals) + u + " for " + f;
    case EncodeErrorKind::NotOnStep:
      return "value " + number(value, decimals) + u + " for " + f + " is not a multiple of " + number(min, decimals) +
             u;
    case EncodeErrorKind::InvalidBits:
      std::snprintf(hex, sizeof hex, "0x%02X", bits);
      if (!(value >= 0) || value != std::round(value) || value > 255)
        return f + ": value " + number(value, 0) + " is not a bit mask 0.." + hex;
      return f + " " + number(value, 0) + " has bits outside the defined mask " + hex;
    case EncodeErrorKind::Unsupported: {
      std::string s = f + " needs firmware " + (needs ? to_string(*needs) : std::string("newer"));
      s += firmware ? " (device has " + to_string(*firmware) + ")" : std::string();
      return s;
    }
    case EncodeErrorKind::NotAGet: return "packet " + f + " has no zero-length get";
    case EncodeErrorKind::EmptyMask: return f + ": no output or group named";
  }
  return f + ": invalid value";
}

}  // namespace pmu::codec
