// Device-side encoders of the solar-boat battery (MG) and MPPT frames: every value of the
// tables in spec/solar-boat-canopen-battery-mppt.txt, with ids, types and resolutions typed
// here from the document (not read from the codec's table), encoded and decoded back with
// codec::canopen::decode; the ends of each type accepted, one step beyond refused.
#include "pmu/codec/canopen_encode.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <limits>
#include <string>
#include <string_view>
#include <vector>

#include "pmu/codec/canopen.hpp"

namespace pmu::codec::canopen::encode_test {
namespace {

// One value of the document's tables: where it goes and what its type and resolution allow.
struct Row {
  std::string_view name;  // canopen::decode()'s name
  std::uint16_t offset;   // battery: COB-ID of node 2; MPPT: 0 base id, 1 base + 1
  std::uint16_t index;    // 0 where the document says "Don't Care"
  std::uint8_t subindex;
  std::uint8_t size;        // bytes of the value
  double lsb;               // resolution in `unit`
  double raw_min, raw_max;  // the type's range in counts
  std::string_view unit;
  double sample;                           // a value in range, in `unit`
  std::vector<std::uint8_t> sample_bytes;  // its little-endian counts
};

constexpr double kI8Min = -128, kI8Max = 127, kU8Max = 255, kU16Max = 65535, kI16Min = -32768, kI16Max = 32767;

// spec "Battery (MG) CAN-format": uint16 1 mV/LSB voltages, int16 10 mA/LSB currents, int8
// 1 %/LSB state of charge, uint16 1 min/LSB time to go, int8 1 degC/LSB temperatures, uint32 BMS
// state; 0x202 Power Level uint8 1 %/LSB.
struct BatteryRow {
  BatteryValue value;
  Row row;
};
const std::vector<BatteryRow> kBatteryRows = {
    {BatteryValue::Voltage, {"voltage", 0x302, 0x2005, 0x01, 2, 0.001, 0, kU16Max, "V", 48.123, {0xFB, 0xBB}}},
    {BatteryValue::Current, {"current", 0x302, 0x2005, 0x02, 2, 0.01, kI16Min, kI16Max, "A", -12.34, {0x2E, 0xFB}}},
    {BatteryValue::CurrentDischarge,
     {"current_discharge", 0x302, 0x2005, 0x03, 2, 0.01, kI16Min, kI16Max, "A", 5.5, {0x26, 0x02}}},
    {BatteryValue::CurrentCharge,
     {"current_charge", 0x302, 0x2005, 0x04, 2, 0.01, kI16Min, kI16Max, "A", 20.0, {0xD0, 0x07}}},
    {BatteryValue::StateOfCharge, {"state_of_charge", 0x302, 0x2005, 0x05, 1, 1, kI8Min, kI8Max, "%", 87, {0x57}}},
    {BatteryValue::TimeToGo, {"time_to_go", 0x302, 0x2005, 0x07, 2, 1, 0, kU16Max, "min", 600, {0x58, 0x02}}},
    {BatteryValue::CellTemperatureHigh,
     {"cell_temperature_high", 0x402, 0x2005, 0x09, 1, 1, kI8Min, kI8Max, "degC", 31, {0x1F}}},
    {BatteryValue::CellTemperatureLow,
     {"cell_temperature_low", 0x402, 0x2005, 0x0B, 1, 1, kI8Min, kI8Max, "degC", -5, {0xFB}}},
    {BatteryValue::CellVoltageHigh,
     {"cell_voltage_high", 0x402, 0x2005, 0x0C, 2, 0.001, 0, kU16Max, "V", 4.105, {0x09, 0x10}}},
    {BatteryValue::CellVoltageLow,
     {"cell_voltage_low", 0x402, 0x2005, 0x0D, 2, 0.001, 0, kU16Max, "V", 3.2, {0x80, 0x0C}}},
    {BatteryValue::BmsState,
     {"bms_state", 0x402, 0x2005, 0x0E, 4, 1, 0, 4294967295.0, "", 0x01020304, {0x04, 0x03, 0x02, 0x01}}},
    {BatteryValue::PowerLevel, {"power_level", 0x202, 0x0000, 0x00, 1, 1, 0, kU8Max, "%", 64, {0x40}}},
};

// spec "MPPT CAN-format": voltages and currents int16 with no resolution (raw counts),
// state uint8, safety/PWM bool, temperature int8 1 degC/LSB, duty cycles uint8 1 %/LSB (the
// third table, on base + 1 as canopen.hpp reads it).
struct MpptRow {
  MpptValue value;
  Row row;
};
Row raw16(std::string_view name, std::uint8_t sub) {
  return {name, 0, 0, sub, 2, 1, kI16Min, kI16Max, "", -1234, {0x2E, 0xFB}};
}
const std::vector<MpptRow> kMpptRows = {
    {MpptValue::VoltageOutputRaw, raw16("voltage_output_raw", 0x00)},
    {MpptValue::CurrentOutputRaw, raw16("current_output_raw", 0x01)},
    {MpptValue::VoltageOutSwRaw, raw16("voltage_out_sw_raw", 0x02)},
    {MpptValue::MpptState, {"mppt_state", 0, 0, 0x03, 1, 1, 0, kU8Max, "", 2, {0x02}}},
    {MpptValue::SafetyEnabled, {"safety_enabled", 0, 0, 0x04, 1, 1, 0, 1, "", 1, {0x01}}},
    {MpptValue::PwmEnabled, {"pwm_enabled", 0, 0, 0x05, 1, 1, 0, 1, "", 1, {0x01}}},
    {MpptValue::Temperature, {"temperature", 0, 0, 0x06, 1, 1, kI8Min, kI8Max, "degC", -20, {0xEC}}},
    {MpptValue::VoltagePanel1Raw, raw16("voltage_panel_1_raw", 0x08)},
    {MpptValue::CurrentPanel1Raw, raw16("current_panel_1_raw", 0x09)},
    {MpptValue::VoltagePanel2Raw, raw16("voltage_panel_2_raw", 0x0A)},
    {MpptValue::CurrentPanel2Raw, raw16("current_panel_2_raw", 0x0B)},
    {MpptValue::VoltagePanel3Raw, raw16("voltage_panel_3_raw", 0x0C)},
    {MpptValue::CurrentPanel3Raw, raw16("current_panel_3_raw", 0x0D)},
    {MpptValue::VoltagePanel4Raw, raw16("voltage_panel_4_raw", 0x0E)},
    {MpptValue::CurrentPanel4Raw, raw16("current_panel_4_raw", 0x0F)},
    {MpptValue::DutyCyclePanel1, {"duty_cycle_panel_1", 1, 0, 0x01, 1, 1, 0, kU8Max, "%", 10, {0x0A}}},
    {MpptValue::DutyCyclePanel2, {"duty_cycle_panel_2", 1, 0, 0x02, 1, 1, 0, kU8Max, "%", 40, {0x28}}},
    {MpptValue::DutyCyclePanel3, {"duty_cycle_panel_3", 1, 0, 0x03, 1, 1, 0, kU8Max, "%", 99, {0x63}}},
    {MpptValue::DutyCyclePanel4, {"duty_cycle_panel_4", 1, 0, 0x04, 1, 1, 0, kU8Max, "%", 100, {0x64}}},
};

std::uint16_t mppt_base(unsigned device) { return static_cast<std::uint16_t>(1254 + device * 8); }

// CANopen expedited upload response for `size` bytes.
std::uint8_t command_for(std::uint8_t size) { return size == 1 ? 0x4F : size == 2 ? 0x4B : 0x43; }

void expect_frame(const Encoded& e, std::uint16_t id, const Row& r, double value, std::uint8_t subindex) {
  ASSERT_TRUE(e.ok()) << e.error().describe();
  const CanFrame& f = *e;
  EXPECT_EQ(f.id, id);
  EXPECT_FALSE(f.extended);
  EXPECT_FALSE(f.remote);
  EXPECT_EQ(f.length, 8);
  EXPECT_EQ(f.data[0], command_for(r.size));
  EXPECT_EQ(f.data[1] | (f.data[2] << 8), r.index);
  EXPECT_EQ(f.data[3], subindex);
  const auto d = canopen::decode(f);
  ASSERT_TRUE(d.ok()) << d.error().describe();
  const Field& last = d->fields[d->field_count - 1u];
  EXPECT_EQ(last.name, r.name);
  EXPECT_EQ(last.unit, r.unit);
  EXPECT_NEAR(last.value, value, r.lsb / 2 + 1e-9);
}

// The document's ends of each type, a sample, and one step beyond either end.
template <class Encode>
void check_row(const Row& r, std::uint16_t id, Encode encode, std::uint8_t subindex) {
  SCOPED_TRACE(std::string(r.name));
  const auto sample = encode(r.sample);
  expect_frame(sample, id, r, r.sample, subindex);
  for (std::size_t i = 0; i < r.sample_bytes.size(); ++i) EXPECT_EQ(sample->data[4 + i], r.sample_bytes[i]) << i;
  for (std::size_t i = 4 + r.sample_bytes.size(); i < 8; ++i) EXPECT_EQ(sample->data[i], 0) << "padding " << i;
  expect_frame(encode(r.raw_min * r.lsb), id, r, r.raw_min * r.lsb, subindex);
  expect_frame(encode(r.raw_max * r.lsb), id, r, r.raw_max * r.lsb, subindex);
  for (double beyond : {(r.raw_min - 1) * r.lsb, (r.raw_max + 1) * r.lsb}) {
    const auto refused = encode(beyond);
    ASSERT_FALSE(refused.ok()) << beyond;
    EXPECT_EQ(refused.error().kind, EncodeErrorKind::OutOfRange);
    EXPECT_EQ(refused.error().field, r.name);
    EXPECT_NEAR(refused.error().min, r.raw_min * r.lsb, 1e-9);
    EXPECT_NEAR(refused.error().max, r.raw_max * r.lsb, 1e-9);
    EXPECT_FALSE(refused.error().describe().empty());
  }
  for (double bad : {std::nan(""), std::numeric_limits<double>::infinity()}) {
    const auto refused = encode(bad);
    ASSERT_FALSE(refused.ok());
    EXPECT_EQ(refused.error().kind, EncodeErrorKind::NotANumber);
  }
}

TEST(CanOpenEncodeBattery, EveryValueRoundTripsAndItsRangeIsEnforced) {
  for (const auto& [value, r] : kBatteryRows) {
    EXPECT_EQ(name_of(value), r.name);
    check_row(
        r, r.offset, [v = value](double x) { return encode_battery(v, x); }, r.subindex);
  }
}

TEST(CanOpenEncodeBattery, ValuesRoundToTheResolution) {
  // 1 mV/LSB: 48.1234 V is 48123 mV; 10 mA/LSB: -1.006 A is -101 counts.
  const auto v = encode_battery(BatteryValue::Voltage, 48.1234);
  ASSERT_TRUE(v.ok());
  EXPECT_EQ(v->data[4] | (v->data[5] << 8), 48123);
  const auto c = encode_battery(BatteryValue::Current, -1.006);
  ASSERT_TRUE(c.ok());
  EXPECT_DOUBLE_EQ(canopen::decode(*c)->fields[0].value, -1.01);
}

TEST(CanOpenEncodeBattery, CellVoltagesCarryTheCellNumberAsSubindex) {
  // spec: 0x482, index 0x2000, subindex "Cell nr", uint16 1 mV/LSB.
  const Row r{"cell_voltage", 0x482, 0x2000, 0, 2, 0.001, 0, kU16Max, "V", 3.7, {0x74, 0x0E}};
  for (unsigned cell : {1u, 2u, 12u, 16u, 255u}) {
    SCOPED_TRACE(cell);
    const auto c = static_cast<std::uint8_t>(cell);
    check_row(
        r, 0x482, [c](double x) { return encode_cell_voltage(c, x); }, c);
    const auto d = canopen::decode(*encode_cell_voltage(c, 3.7));
    ASSERT_TRUE(d.ok());
    EXPECT_EQ(d->fields[0].name, "cell");
    EXPECT_DOUBLE_EQ(d->fields[0].value, cell);
  }
}

TEST(CanOpenEncodeBattery, TemperatureCollectionIsFourUint8) {
  // spec: 0x402/0x0F "Temperature Collection", 4x uint8_t 1 degC/LSB.
  const auto e = encode_temperature_collection({20, 21.4, 0, 255});
  ASSERT_TRUE(e.ok()) << e.error().describe();
  EXPECT_EQ(e->id, 0x402u);
  EXPECT_EQ(e->data[0], 0x43);
  EXPECT_EQ(e->data[3], 0x0F);
  const auto d = canopen::decode(*e);
  ASSERT_TRUE(d.ok());
  ASSERT_EQ(d->field_count, 4);
  const double expected[4] = {20, 21, 0, 255};
  for (std::size_t i = 0; i < 4; ++i) {
    EXPECT_EQ(d->fields[i].name, "temperature_" + std::to_string(i + 1));
    EXPECT_EQ(d->fields[i].unit, "degC");
    EXPECT_DOUBLE_EQ(d->fields[i].value, expected[i]);
  }
  for (const auto& bad : {std::array<double, 4>{20, 20, 20, -1}, std::array<double, 4>{256, 20, 20, 20}}) {
    const auto refused = encode_temperature_collection(bad);
    ASSERT_FALSE(refused.ok());
    EXPECT_EQ(refused.error().kind, EncodeErrorKind::OutOfRange);
    EXPECT_EQ(refused.error().field.substr(0, 12), "temperature_");
  }
}

TEST(CanOpenEncodeBattery, NodeIdIsTheLowBitsOfTheCobId) {
  // "Function code | Node ID": node 2 gives the document's ids; node 5 the same functions.
  const std::pair<std::uint8_t, std::uint32_t> cases[] = {{2, 0x302}, {5, 0x305}, {1, 0x301}, {127, 0x37F}};
  for (const auto& [node, id] : cases) {
    const auto e = encode_battery(BatteryValue::Voltage, 48.0, node);
    ASSERT_TRUE(e.ok());
    EXPECT_EQ(e->id, id);
  }
  EXPECT_EQ(encode_battery(BatteryValue::PowerLevel, 1, 5)->id, 0x205u);
  EXPECT_EQ(encode_battery(BatteryValue::BmsState, 1, 5)->id, 0x405u);
  EXPECT_EQ(encode_cell_voltage(1, 3.0, 5)->id, 0x485u);
  EXPECT_EQ(encode_temperature_collection({1, 2, 3, 4}, 5)->id, 0x405u);
  for (std::uint8_t node : {std::uint8_t{0}, std::uint8_t{128}, std::uint8_t{255}}) {
    const auto refused = encode_battery(BatteryValue::Voltage, 48.0, node);
    ASSERT_FALSE(refused.ok());
    EXPECT_EQ(refused.error().field, "node");
    EXPECT_FALSE(encode_cell_voltage(1, 3.0, node).ok());
    EXPECT_FALSE(encode_temperature_collection({1, 2, 3, 4}, node).ok());
  }
}

TEST(CanOpenEncodeMppt, EveryValueOfEveryDeviceRoundTrips) {
  for (std::uint8_t device = 0; device < 8; ++device) {
    SCOPED_TRACE(int{device});
    for (const auto& [value, r] : kMpptRows) {
      EXPECT_EQ(name_of(value), r.name);
      const auto id = static_cast<std::uint16_t>(mppt_base(device) + r.offset);
      check_row(
          r, id, [device, v = value](double x) { return encode_mppt(device, v, x); }, r.subindex);
      const auto d = canopen::decode(*encode_mppt(device, value, r.sample));
      ASSERT_TRUE(d.ok());
      EXPECT_EQ(d->device, device);
      EXPECT_EQ(d->source, Source::Mppt);
    }
  }
}

TEST(CanOpenEncodeMppt, ChannelActiveMap) {
  const auto e = encode_channel_active_map(3, {1, 0, 1, 1});
  ASSERT_TRUE(e.ok());
  EXPECT_EQ(e->id, mppt_base(3) + 1u);
  EXPECT_EQ(e->data[3], 0x05);
  const auto d = canopen::decode(*e);
  ASSERT_TRUE(d.ok()) << d.error().describe();
  ASSERT_EQ(d->field_count, 4);
  const double expected[4] = {1, 0, 1, 1};
  for (std::size_t i = 0; i < 4; ++i) {
    EXPECT_EQ(d->fields[i].name, "channel_" + std::to_string(i + 1) + "_active");
    EXPECT_DOUBLE_EQ(d->fields[i].value, expected[i]);
  }
}

TEST(CanOpenEncodeMppt, DeviceOutsideZeroToSevenIsRefused) {
  for (std::uint8_t device : {std::uint8_t{8}, std::uint8_t{255}}) {
    const auto refused = encode_mppt(device, MpptValue::Temperature, 20);
    ASSERT_FALSE(refused.ok());
    EXPECT_EQ(refused.error().kind, EncodeErrorKind::OutOfRange);
    EXPECT_EQ(refused.error().field, "device");
    EXPECT_FALSE(encode_channel_active_map(device, {1, 1, 1, 1}).ok());
  }
}

TEST(CanOpenEncode, HeaderExamples) {
  // The worked examples of canopen_encode.hpp, byte for byte.
  struct Example {
    const char* what;
    Encoded frame;
    std::uint32_t id;
    std::array<std::uint8_t, 8> data;
  };
  const Example examples[] = {
      {"voltage 48.123 V",
       encode_battery(BatteryValue::Voltage, 48.123),
       0x302,
       {0x4B, 0x05, 0x20, 0x01, 0xFB, 0xBB, 0x00, 0x00}},
      {"cell 3 3.7 V", encode_cell_voltage(3, 3.7), 0x482, {0x4B, 0x00, 0x20, 0x03, 0x74, 0x0E, 0x00, 0x00}},
      {"MPPT 1 duty 2 40 %",
       encode_mppt(1, MpptValue::DutyCyclePanel2, 40),
       0x4EF,
       {0x4F, 0x00, 0x00, 0x02, 0x28, 0x00, 0x00, 0x00}},
  };
  for (const auto& x : examples) {
    SCOPED_TRACE(x.what);
    ASSERT_TRUE(x.frame.ok());
    EXPECT_EQ(x.frame->id, x.id);
    EXPECT_EQ(x.frame->length, 8);
    EXPECT_EQ(x.frame->data, x.data);
  }
}

}  // namespace
}  // namespace pmu::codec::canopen::encode_test
