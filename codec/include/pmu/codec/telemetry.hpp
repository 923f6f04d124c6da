#pragma once
// The measured-value packets 0x00..0x03 as tables: where each field sits in the frame, its
// wire type, scale, range and unit, and which member of the typed struct (messages.hpp) it
// fills. The decoder, the device-side encoder, pmuctl's field listing and the simulator's
// clamping all read these rows, so a scale or a range is written once. The unit tests keep
// their own values typed from the spec's tables, so a wrong row here fails there.
//
// Packet 0x04 is not a table of scaled fields: its flags change meaning with firmware
// (firmware.hpp), so decode_status/encode_status spell it out.

#include <array>
#include <cstdint>
#include <string_view>

#include "pmu/codec/ids.hpp"
#include "pmu/codec/messages.hpp"

namespace pmu::codec {

enum class WireType : std::uint8_t { U8, S8, U16BE, S16BE };

constexpr std::uint8_t wire_size(WireType t) noexcept {
  switch (t) {
    case WireType::U8:
    case WireType::S8: return 1;
    case WireType::U16BE:
    case WireType::S16BE: return 2;
  }
  return 2;
}

// "No sensor" on the wire (table 5): said of the external sensors, and taken to mean the
// same for every temperature (interface.md 1.1), since a reading of -128 degC on the internal
// or starter sensor is no reading either.
inline constexpr std::int8_t kNoSensorRaw = -128;

template <class Packet, class Value = double>
struct FieldSpec {
  std::string_view name;  // interface.md's field name; also EncodeError::field
  std::uint8_t offset;    // first data byte
  WireType wire;
  double divisor;                 // value = raw / divisor; the resolution is 1 / divisor
  std::int32_t raw_min, raw_max;  // what a reading can be (the spec's "Range"), raw units
  std::string_view unit;
  Value Packet::*member;
  // A 1.12+ external sensor (v1.9 6.1): before 1.12 the field is not reported at all.
  bool external_sensor = false;
  // A temperature: kNoSensorRaw on the wire is "no sensor" (NaN), so a reading stops at -127.
  bool no_sensor = false;

  constexpr double min() const noexcept { return static_cast<double>(raw_min) / divisor; }
  constexpr double max() const noexcept { return static_cast<double>(raw_max) / divisor; }
};

// A reading beyond what the field can carry, reported at the field's limit (what a unit
// whose sensor reads past the range sends). NaN passes: for a temperature it is "no
// sensor", elsewhere the encoder refuses it.
template <class Packet, class Value>
constexpr double clamp_to_field(const FieldSpec<Packet, Value>& f, double v) noexcept {
  if (v != v) return v;
  if (v < f.min()) return f.min();
  if (v > f.max()) return f.max();
  return v;
}

template <class Packet>
struct Telemetry;  // one specialisation per table below

// Protocol v1.9 table 2: 0.1 V, except the 28 V output (0.2 V) and the generator (0.4 V).
template <>
struct Telemetry<Voltages> {
  static constexpr PacketId packet = PacketId::Voltages;
  static constexpr std::array<FieldSpec<Voltages>, 7> fields{{
      {"avionics", 0, WireType::U8, 10, 0, 250, "V", &Voltages::avionics},
      {"output_28v", 1, WireType::U8, 5, 0, 250, "V", &Voltages::output_28v},
      {"payload", 2, WireType::U8, 10, 0, 250, "V", &Voltages::payload},
      {"servo", 3, WireType::U8, 10, 0, 125, "V", &Voltages::servo},
      {"battery_a", 4, WireType::U8, 10, 0, 250, "V", &Voltages::battery_a},
      {"battery_b", 5, WireType::U8, 10, 0, 250, "V", &Voltages::battery_b},
      {"generator", 6, WireType::U8, 2.5, 0, 250, "V", &Voltages::generator},
  }};
};

// Protocol v1.9 table 3: 0.1 A; the 28 V output and the batteries are signed (charging +).
template <>
struct Telemetry<Currents> {
  static constexpr PacketId packet = PacketId::Currents;
  static constexpr std::array<FieldSpec<Currents>, 6> fields{{
      {"avionics", 0, WireType::U8, 10, 0, 100, "A", &Currents::avionics},
      {"output_28v", 1, WireType::S8, 10, -125, 125, "A", &Currents::output_28v},
      {"payload", 2, WireType::U8, 10, 0, 100, "A", &Currents::payload},
      {"servo", 3, WireType::U8, 10, 0, 100, "A", &Currents::servo},
      {"battery_a", 4, WireType::S8, 10, -125, 125, "A", &Currents::battery_a},
      {"battery_b", 5, WireType::S8, 10, -125, 125, "A", &Currents::battery_b},
  }};
};

// Protocol v1.9 table 4: signed 16-bit mAh counts, big-endian (section 5).
template <>
struct Telemetry<BatteryEnergy> {
  static constexpr PacketId packet = PacketId::BatteryEnergy;
  static constexpr std::array<FieldSpec<BatteryEnergy, std::int16_t>, 2> fields{{
      {"battery_a_mah", 0, WireType::S16BE, 1, -32768, 32767, "mAh", &BatteryEnergy::battery_a_mah},
      {"battery_b_mah", 2, WireType::S16BE, 1, -32768, 32767, "mAh", &BatteryEnergy::battery_b_mah},
  }};
};

// Protocol v1.9 table 5: signed whole degrees; the starter sensor reads -49..127. The
// internal sensor's -128..127 loses -128 to "no sensor", like the external ones.
template <>
struct Telemetry<Temperatures> {
  static constexpr PacketId packet = PacketId::Temperatures;
  static constexpr std::array<FieldSpec<Temperatures>, 5> fields{{
      {"internal", 0, WireType::S8, 1, -127, 127, "degC", &Temperatures::internal, false, true},
      {"battery_a", 1, WireType::S8, 1, -127, 127, "degC", &Temperatures::battery_a, true, true},
      {"battery_b", 2, WireType::S8, 1, -127, 127, "degC", &Temperatures::battery_b, true, true},
      {"generator", 3, WireType::S8, 1, -127, 127, "degC", &Temperatures::generator, true, true},
      {"starter", 4, WireType::S8, 1, -49, 127, "degC", &Temperatures::starter, false, true},
  }};
};

// Every field of `p` clamped into its range (clamp_to_field); for the packets of doubles.
template <class Packet>
constexpr Packet clamped_to_fields(Packet p) noexcept {
  for (const auto& f : Telemetry<Packet>::fields) p.*f.member = clamp_to_field(f, p.*f.member);
  return p;
}

}  // namespace pmu::codec
