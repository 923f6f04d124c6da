// The codec's own tables (packets.hpp, telemetry.hpp) checked for consistency with the
// codec's behaviour. Whether their values match the spec is telemetry_packets_test's job,
// which types them from protocol v1.9 tables 1..5 independently; here: every row
// round-trips, the rows of a packet tile its frame, and names and ids map both ways.
#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <utility>
#include <set>
#include <string>
#include <type_traits>
#include <vector>

#include "pmu/codec/decode.hpp"
#include "pmu/codec/encode.hpp"
#include "pmu/codec/packets.hpp"
#include "pmu/codec/telemetry.hpp"

namespace pmu::codec {
namespace {

// ---- table 1 -----------------------------------------------------------------------------
TEST(PacketTable, IdsAndNamesAreUniqueAndMapBothWays) {
  std::set<PacketId> ids;
  std::set<std::string_view> names;
  for (const auto& p : kPacketTable) {
    SCOPED_TRACE(std::string(p.name));
    EXPECT_TRUE(ids.insert(p.id).second);
    EXPECT_TRUE(names.insert(p.name).second);
    EXPECT_EQ(packet_name(p.id), p.name);
    EXPECT_EQ(packet_from_name(p.name), p.id);
    EXPECT_TRUE(is_known_packet(static_cast<std::uint8_t>(p.id)));
    EXPECT_EQ(data_length(p.id), p.length);
    EXPECT_EQ(has_zero_length_get(p.id), p.zero_length_get);
  }
}

TEST(PacketTable, IdsOutsideTable1HaveNoRow) {
  for (int raw = 0; raw <= 0xFF; ++raw) {
    const auto id = static_cast<PacketId>(raw);
    if (find_packet(id)) continue;
    SCOPED_TRACE(raw);
    EXPECT_FALSE(is_known_packet(static_cast<std::uint8_t>(raw)));
    EXPECT_EQ(packet_name(id), "unknown");
    EXPECT_EQ(data_length(id), 0);
    EXPECT_FALSE(has_zero_length_get(id));
  }
  EXPECT_EQ(packet_from_name("unknown"), std::nullopt);
}

TEST(PacketTable, ParameterWidthsAreTheirPacketsLengths) {
  for (const auto& s : parameter_table()) {
    SCOPED_TRACE(std::string(s.name));
    EXPECT_EQ(data_length(s.packet), s.width);
    EXPECT_EQ(packet_name(s.packet), s.name);
  }
}

// ---- ids ---------------------------------------------------------------------------------
TEST(AddressOfId, LowSixteenBitsWhateverThePacket) {
  EXPECT_EQ(address_of_id(0x1E000001u), 1);
  EXPECT_EQ(address_of_id(0x1E31FFFFu), kBroadcastAddress);
  EXPECT_EQ(address_of_id(0x1E1A0102u), 0x0102);  // 0x1A: not in table 1, address still readable
  EXPECT_EQ(address_of_id(make_id(PacketId::Reset, 0xFFFE)), 0xFFFE);
}

// ---- tables 2..5 -------------------------------------------------------------------------
// A telemetry packet whose field `f` holds `value` and every other field a legal zero.
template <class Packet, class Field>
Packet with(const Field& f, double value) {
  Packet p{};
  for (const auto& g : Telemetry<Packet>::fields) p.*g.member = 0;
  using Value = std::remove_reference_t<decltype(p.*f.member)>;
  p.*f.member = static_cast<Value>(value);
  return p;
}

template <class Packet>
Encoded encode(const Packet& p) {
  if constexpr (std::is_same_v<Packet, Voltages>) return encode_voltages(p, 1);
  if constexpr (std::is_same_v<Packet, Currents>) return encode_currents(p, 1);
  if constexpr (std::is_same_v<Packet, BatteryEnergy>) return encode_battery_energy(p, 1);
  if constexpr (std::is_same_v<Packet, Temperatures>) return encode_temperatures(p, 1);
}

template <class Packet>
void expect_fields_tile_the_frame() {
  const PacketId id = Telemetry<Packet>::packet;
  std::vector<int> owner(data_length(id), 0);
  for (const auto& f : Telemetry<Packet>::fields) {
    SCOPED_TRACE(std::string(f.name));
    ASSERT_LE(f.offset + wire_size(f.wire), owner.size());
    for (std::size_t b = f.offset; b < f.offset + wire_size(f.wire); ++b) ++owner[b];
  }
  for (std::size_t b = 0; b < owner.size(); ++b) EXPECT_EQ(owner[b], 1) << packet_name(id) << " byte " << b;
}

TEST(TelemetryTables, FieldsCoverEachDataByteExactlyOnce) {
  expect_fields_tile_the_frame<Voltages>();
  expect_fields_tile_the_frame<Currents>();
  expect_fields_tile_the_frame<BatteryEnergy>();
  expect_fields_tile_the_frame<Temperatures>();
}

template <class Packet>
void expect_range_round_trips() {
  for (const auto& f : Telemetry<Packet>::fields) {
    const double step = 1.0 / f.divisor;
    for (double v : {f.min(), f.min() + step, f.max() - step, f.max()}) {
      SCOPED_TRACE(testing::Message() << packet_name(Telemetry<Packet>::packet) << "." << f.name << " = " << v);
      auto frame = encode(with<Packet>(f, v));
      ASSERT_TRUE(frame.ok()) << frame.error().describe();
      EXPECT_EQ(frame->length, data_length(Telemetry<Packet>::packet));
      auto m = decode(*frame);
      ASSERT_TRUE(m.ok()) << m.error().describe();
      EXPECT_DOUBLE_EQ(static_cast<double>(std::get<Packet>(m->payload).*f.member), v);
    }
  }
}

TEST(TelemetryTables, EveryFieldRoundTripsAtItsEndsAndOneStepIn) {
  expect_range_round_trips<Voltages>();
  expect_range_round_trips<Currents>();
  expect_range_round_trips<BatteryEnergy>();
  expect_range_round_trips<Temperatures>();
}

template <class Packet>
void expect_one_step_out_refused() {
  for (const auto& f : Telemetry<Packet>::fields) {
    const double step = 1.0 / f.divisor;
    for (double v : {f.min() - step, f.max() + step}) {
      SCOPED_TRACE(testing::Message() << f.name << " = " << v);
      auto frame = encode(with<Packet>(f, v));
      ASSERT_FALSE(frame.ok());
      EXPECT_EQ(frame.error().kind, EncodeErrorKind::OutOfRange);
      EXPECT_EQ(frame.error().field, f.name);
      EXPECT_EQ(frame.error().unit, f.unit);
      EXPECT_DOUBLE_EQ(frame.error().min, f.min());
      EXPECT_DOUBLE_EQ(frame.error().max, f.max());
    }
  }
}

TEST(TelemetryTables, OneStepBeyondEitherEndIsRefusedNamingTheField) {
  expect_one_step_out_refused<Voltages>();
  expect_one_step_out_refused<Currents>();
  expect_one_step_out_refused<Temperatures>();
}

TEST(TelemetryTables, EveryTemperatureIsANoSensorField) {
  for (const auto& f : Telemetry<Temperatures>::fields) {
    SCOPED_TRACE(std::string(f.name));
    EXPECT_TRUE(f.no_sensor);
    auto frame = encode(with<Temperatures>(f, kNoSensor));
    ASSERT_TRUE(frame.ok());
    EXPECT_EQ(frame->data[f.offset], 0x80);
    EXPECT_TRUE(std::isnan(std::get<Temperatures>(decode(*frame)->payload).*f.member));
  }
}

TEST(TelemetryTables, ClampToFieldStopsAtTheRangeAndPassesNaN) {
  for (const auto& f : Telemetry<Currents>::fields) {
    EXPECT_EQ(clamp_to_field(f, -1e9), f.min());
    EXPECT_EQ(clamp_to_field(f, 1e9), f.max());
    EXPECT_EQ(clamp_to_field(f, f.min() + 0.1), f.min() + 0.1);
    EXPECT_TRUE(std::isnan(clamp_to_field(f, kNoSensor)));
  }
  Voltages v;
  v.generator = 1000;
  v.servo = -3;
  const Voltages c = clamped_to_fields(v);
  EXPECT_EQ(c.generator, 100.0);
  EXPECT_EQ(c.servo, 0.0);
}

// ---- output and group names (interface.md; tables 7, 13, 19..21) ---------------------------
TEST(Names, OutputsByNameAndBack) {
  const std::pair<const char*, std::uint8_t> typed[] = {
      {"avionics_servo", 0x01}, {"payload", 0x02}, {"charger_a", 0x04}, {"charger_b", 0x08}};
  for (const auto& [name, bit] : typed) {
    EXPECT_EQ(bit_named(kOutputNames, name), bit) << name;
    EXPECT_EQ(names_of(kOutputNames, bit), name);
  }
  EXPECT_EQ(bit_named(kOutputNames, "charger_c"), std::nullopt);
  EXPECT_EQ(bit_named(kOutputNames, "voltages"), std::nullopt);
  EXPECT_EQ(names_of(kOutputNames, 0x05), "avionics_servo,charger_a");
  EXPECT_EQ(names_of(kOutputNames, 0x00), "");
  EXPECT_EQ(names_of(kOutputNames, 0xF0), "");  // undefined bits have no name
  EXPECT_EQ(names_of(kOutputNames, output_bit::All, ", "), "avionics_servo, payload, charger_a, charger_b");
}

TEST(Names, GroupsByNameAndBack) {
  const std::pair<const char*, std::uint8_t> typed[] = {
      {"voltages", 0x01}, {"currents", 0x02}, {"battery_energy", 0x04}, {"temperatures", 0x08}, {"status", 0x10}};
  for (const auto& [name, bit] : typed) {
    EXPECT_EQ(bit_named(kGroupNames, name), bit) << name;
    EXPECT_EQ(names_of(kGroupNames, bit), name);
  }
  EXPECT_EQ(bit_named(kGroupNames, "payload"), std::nullopt);
  EXPECT_EQ(names_of(kGroupNames, group_bit::All, ", "), "voltages, currents, battery_energy, temperatures, status");
}

template <std::size_t N>
void expect_bits_tile(const std::array<NamedBit, N>& table, std::uint8_t all) {
  std::uint8_t seen = 0;
  for (const auto& b : table) {
    EXPECT_EQ(b.bit & (b.bit - 1), 0) << b.name << " is one bit";
    EXPECT_EQ(seen & b.bit, 0) << b.name;
    seen = static_cast<std::uint8_t>(seen | b.bit);
  }
  EXPECT_EQ(seen, all);
}

TEST(Names, EachDefinedBitHasExactlyOneName) {
  expect_bits_tile(kOutputNames, output_bit::All);
  expect_bits_tile(kGroupNames, group_bit::All);
}

// ---- durations (tables 12 and 17: 0.1 s steps) --------------------------------------------
TEST(Durations, PacketPeriodAndCrankingTimeInMilliseconds) {
  using std::chrono::milliseconds;
  EXPECT_EQ(duration_value(Parameter::PacketPeriod, milliseconds(1500)), 1.5);
  EXPECT_EQ(duration_value(Parameter::CrankingTime, milliseconds(100)), 0.1);
  EXPECT_EQ(duration_of(Parameter::PacketPeriod, 15), milliseconds(1500));
  EXPECT_EQ(duration_of(Parameter::CrankingTime, 0), milliseconds(0));
  for (std::uint32_t raw = 1; raw <= 255; ++raw) {
    SCOPED_TRACE(raw);
    EXPECT_EQ(duration_of(Parameter::PacketPeriod, raw), milliseconds(raw * 100));
    const auto back = to_raw(Parameter::PacketPeriod, duration_value(Parameter::PacketPeriod, milliseconds(raw * 100)));
    ASSERT_TRUE(back.ok());
    EXPECT_EQ(*back, raw);
  }
  // 0.15 s is between two steps: refused, not rounded.
  EXPECT_FALSE(to_raw(Parameter::PacketPeriod, duration_value(Parameter::PacketPeriod, milliseconds(150))).ok());
}

TEST(Durations, OtherParametersAreNotDurations) {
  EXPECT_TRUE(std::isnan(duration_value(Parameter::AvionicsVoltage, std::chrono::milliseconds(1000))));
  EXPECT_EQ(duration_of(Parameter::UpperTemperatureLimit, 80), std::chrono::milliseconds(0));
  EXPECT_FALSE(
      to_raw(Parameter::AvionicsVoltage, duration_value(Parameter::AvionicsVoltage, std::chrono::seconds(12))).ok());
}

}  // namespace
}  // namespace pmu::codec
