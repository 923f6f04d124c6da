// Solar-boat battery (MG) and MPPT frames, decode only: every row of the tables in
// spec/solar-boat-canopen-battery-mppt.txt, with the values worked out by hand from the
// spec's type and resolution columns (never copied from the decoder), plus the readings
// canopen.hpp documents for what the document leaves open (byte order, Data[0], the third
// MPPT table on base + 1).
#include "pmu/codec/canopen.hpp"

#include <gtest/gtest.h>

#include <cstdint>
#include <initializer_list>
#include <string>
#include <string_view>
#include <vector>

namespace pmu::codec::canopen::decode_test {
namespace {

// ---- helpers -------------------------------------------------------------------------------

// The spec's "CANopen format" data layout:
//   Data[0] Node-ID | Data[1] Index Low | Data[2] Index High | Data[3] Subindex | Data[4..7] Data
std::vector<std::uint8_t> payload(std::uint8_t data0, std::uint16_t index, std::uint8_t subindex,
                                  std::initializer_list<std::uint8_t> value) {
  std::vector<std::uint8_t> p{data0, static_cast<std::uint8_t>(index & 0xFFu), static_cast<std::uint8_t>(index >> 8),
                              subindex};
  for (std::uint8_t b : value) p.push_back(b);
  return p;
}

CanFrame frame11(std::uint32_t id, const std::vector<std::uint8_t>& bytes) {
  CanFrame f;
  f.id = id;
  f.length = static_cast<std::uint8_t>(bytes.size());
  for (std::size_t i = 0; i < bytes.size() && i < kMaxDataLength; ++i) f.data[i] = bytes[i];
  return f;
}

// MPPT "can_base_id = 1254 + (device_id * 8)" (spec, "MPPT CAN-format"), kept in decimal as
// the document writes it.
std::uint16_t mppt_base(unsigned device) { return static_cast<std::uint16_t>(1254 + device * 8); }

struct Expected {
  std::string_view name;
  double value;
  std::string_view unit;
};

struct Row {
  std::string label;  // test name suffix
  std::uint16_t cob_id;
  std::vector<std::uint8_t> data;  // Data[0..length)
  Source source;
  std::uint8_t device;
  std::vector<Expected> fields;
};

std::ostream& operator<<(std::ostream& os, const Row& r) { return os << r.label; }

void expect_row(const Row& row, const CanFrame& f) {
  const auto r = canopen::decode(f);
  ASSERT_TRUE(r.ok()) << r.error().describe();
  const CanOpenMessage& m = r.value();
  EXPECT_EQ(m.source, row.source);
  EXPECT_EQ(m.cob_id, row.cob_id);
  EXPECT_EQ(m.device, row.device);
  // Data[0] is reported as is; Data[1..2] are the index, low byte first (spec layout).
  EXPECT_EQ(m.command_byte, row.data[0]);
  EXPECT_EQ(int{m.index}, row.data[1] | (row.data[2] << 8));
  EXPECT_EQ(m.subindex, row.data[3]);
  ASSERT_EQ(std::size_t{m.field_count}, row.fields.size());
  for (std::size_t i = 0; i < row.fields.size(); ++i) {
    SCOPED_TRACE(row.fields[i].name);
    EXPECT_EQ(m.fields[i].name, row.fields[i].name);
    EXPECT_DOUBLE_EQ(m.fields[i].value, row.fields[i].value);
    EXPECT_EQ(m.fields[i].unit, row.fields[i].unit);
  }
}

class CanOpenRow : public ::testing::TestWithParam<Row> {};

// Each row decodes from the shortest frame that holds its value, and from a full 8-byte
// frame whose unused bytes are filler (what a device padding its frames would send).
TEST_P(CanOpenRow, DecodesToSiValues) {
  const Row& row = GetParam();
  {
    SCOPED_TRACE("exact length");
    expect_row(row, frame11(row.cob_id, row.data));
  }
  {
    SCOPED_TRACE("padded to 8 bytes");
    std::vector<std::uint8_t> padded = row.data;
    padded.resize(kMaxDataLength, 0xA5);
    expect_row(row, frame11(row.cob_id, padded));
  }
  EXPECT_TRUE(is_canopen_id(row.cob_id, false));
}

std::string row_name(const ::testing::TestParamInfo<Row>& info) { return info.param.label; }

// ---- battery ---------------------------------------------------------------------------------
// spec: "Battery (MG) CAN-format" table. Resolutions: voltages 1 mV/LSB, currents 10 mA/LSB,
// state of charge 1 %/LSB, time to go 1 min/LSB, temperatures 1 degC/LSB, BMS state raw.
// Data[0] varies from row to row: it is not checked.
Row battery(std::string label, std::uint16_t id, std::uint8_t data0, std::uint16_t index, std::uint8_t sub,
            std::initializer_list<std::uint8_t> value, std::vector<Expected> fields) {
  return Row{std::move(label), id, payload(data0, index, sub, value), Source::Battery, 0, std::move(fields)};
}

const std::vector<Row> kBatteryRows = {
    // 0x302, index 0x2005
    battery("B302_01_voltage_12345mV", 0x302, 0x40, 0x2005, 0x01, {0x39, 0x30}, {{"voltage", 12.345, "V"}}),
    battery("B302_01_voltage_zero", 0x302, 0x00, 0x2005, 0x01, {0x00, 0x00}, {{"voltage", 0.0, "V"}}),
    battery("B302_01_voltage_uint16_max", 0x302, 0x4B, 0x2005, 0x01, {0xFF, 0xFF}, {{"voltage", 65.535, "V"}}),
    battery("B302_02_current_minus_10A", 0x302, 0x43, 0x2005, 0x02, {0x18, 0xFC}, {{"current", -10.0, "A"}}),
    battery("B302_02_current_plus_10A", 0x302, 0x43, 0x2005, 0x02, {0xE8, 0x03}, {{"current", 10.0, "A"}}),
    battery("B302_02_current_int16_max", 0x302, 0x4B, 0x2005, 0x02, {0xFF, 0x7F}, {{"current", 327.67, "A"}}),
    battery("B302_02_current_int16_min", 0x302, 0x4B, 0x2005, 0x02, {0x00, 0x80}, {{"current", -327.68, "A"}}),
    battery("B302_03_discharge_int16_max", 0x302, 0xFF, 0x2005, 0x03, {0xFF, 0x7F},
            {{"current_discharge", 327.67, "A"}}),
    battery("B302_03_discharge_int16_min", 0x302, 0x60, 0x2005, 0x03, {0x00, 0x80},
            {{"current_discharge", -327.68, "A"}}),
    battery("B302_04_charge_5A", 0x302, 0x80, 0x2005, 0x04, {0xF4, 0x01}, {{"current_charge", 5.0, "A"}}),
    battery("B302_04_charge_int16_max", 0x302, 0x80, 0x2005, 0x04, {0xFF, 0x7F}, {{"current_charge", 327.67, "A"}}),
    battery("B302_04_charge_int16_min", 0x302, 0x80, 0x2005, 0x04, {0x00, 0x80}, {{"current_charge", -327.68, "A"}}),
    battery("B302_05_soc_75", 0x302, 0x4F, 0x2005, 0x05, {0x4B}, {{"state_of_charge", 75.0, "%"}}),
    battery("B302_05_soc_int8_max", 0x302, 0x4F, 0x2005, 0x05, {0x7F}, {{"state_of_charge", 127.0, "%"}}),
    battery("B302_05_soc_int8_min", 0x302, 0x4F, 0x2005, 0x05, {0x80}, {{"state_of_charge", -128.0, "%"}}),
    battery("B302_05_soc_minus_1", 0x302, 0x4F, 0x2005, 0x05, {0xFF}, {{"state_of_charge", -1.0, "%"}}),
    battery("B302_07_time_to_go_1000", 0x302, 0x4B, 0x2005, 0x07, {0xE8, 0x03}, {{"time_to_go", 1000.0, "min"}}),
    // uint16: 0x8000 and 0xFFFF are large positive numbers, not negative.
    battery("B302_07_time_to_go_32768", 0x302, 0x4B, 0x2005, 0x07, {0x00, 0x80}, {{"time_to_go", 32768.0, "min"}}),
    battery("B302_07_time_to_go_uint16_max", 0x302, 0x4B, 0x2005, 0x07, {0xFF, 0xFF}, {{"time_to_go", 65535.0, "min"}}),
    // 0x402, index 0x2005
    battery("B402_09_temp_high_25", 0x402, 0x40, 0x2005, 0x09, {0x19}, {{"cell_temperature_high", 25.0, "degC"}}),
    battery("B402_09_temp_high_int8_max", 0x402, 0x40, 0x2005, 0x09, {0x7F},
            {{"cell_temperature_high", 127.0, "degC"}}),
    battery("B402_09_temp_high_int8_min", 0x402, 0x40, 0x2005, 0x09, {0x80},
            {{"cell_temperature_high", -128.0, "degC"}}),
    battery("B402_0B_temp_low_minus_10", 0x402, 0x00, 0x2005, 0x0B, {0xF6}, {{"cell_temperature_low", -10.0, "degC"}}),
    battery("B402_0B_temp_low_int8_max", 0x402, 0x00, 0x2005, 0x0B, {0x7F}, {{"cell_temperature_low", 127.0, "degC"}}),
    battery("B402_0B_temp_low_int8_min", 0x402, 0x00, 0x2005, 0x0B, {0x80}, {{"cell_temperature_low", -128.0, "degC"}}),
    battery("B402_0C_cell_high_3600mV", 0x402, 0x43, 0x2005, 0x0C, {0x10, 0x0E}, {{"cell_voltage_high", 3.6, "V"}}),
    battery("B402_0C_cell_high_uint16_max", 0x402, 0x43, 0x2005, 0x0C, {0xFF, 0xFF},
            {{"cell_voltage_high", 65.535, "V"}}),
    battery("B402_0D_cell_low_3000mV", 0x402, 0x4B, 0x2005, 0x0D, {0xB8, 0x0B}, {{"cell_voltage_low", 3.0, "V"}}),
    battery("B402_0D_cell_low_32768mV", 0x402, 0x4B, 0x2005, 0x0D, {0x00, 0x80}, {{"cell_voltage_low", 32.768, "V"}}),
    battery("B402_0E_bms_state", 0x402, 0x43, 0x2005, 0x0E, {0x78, 0x56, 0x34, 0x12},
            {{"bms_state", 305419896.0, ""}}),  // 0x12345678
    battery("B402_0E_bms_state_uint32_max", 0x402, 0x43, 0x2005, 0x0E, {0xFF, 0xFF, 0xFF, 0xFF},
            {{"bms_state", 4294967295.0, ""}}),
    battery("B402_0F_temperature_collection", 0x402, 0x43, 0x2005, 0x0F, {0x14, 0x15, 0x16, 0xFF},
            {{"temperature_1", 20.0, "degC"},
             {"temperature_2", 21.0, "degC"},
             {"temperature_3", 22.0, "degC"},
             {"temperature_4", 255.0, "degC"}}),  // uint8: 0xFF is 255, not -1
    // 0x482, index 0x2000, subindex = cell number: the cell first, then its voltage.
    battery("B482_cell_1_3451mV", 0x482, 0x43, 0x2000, 0x01, {0x7B, 0x0D},
            {{"cell", 1.0, ""}, {"cell_voltage", 3.451, "V"}}),
    battery("B482_cell_16_zero", 0x482, 0x00, 0x2000, 0x10, {0x00, 0x00},
            {{"cell", 16.0, ""}, {"cell_voltage", 0.0, "V"}}),
    battery("B482_cell_0", 0x482, 0x00, 0x2000, 0x00, {0x88, 0x13}, {{"cell", 0.0, ""}, {"cell_voltage", 5.0, "V"}}),
    battery("B482_cell_255_uint16_max", 0x482, 0xFF, 0x2000, 0xFF, {0xFF, 0xFF},
            {{"cell", 255.0, ""}, {"cell_voltage", 65.535, "V"}}),
    // 0x202, index and subindex "Don't Care": the value is Data[4].
    battery("B202_power_level_100", 0x202, 0x00, 0x0000, 0x00, {0x64}, {{"power_level", 100.0, "%"}}),
    battery("B202_power_level_uint8_max_any_index", 0x202, 0x12, 0xABCD, 0xEF, {0xFF}, {{"power_level", 255.0, "%"}}),
    battery("B202_power_level_zero_battery_index", 0x202, 0x40, 0x2005, 0x01, {0x00}, {{"power_level", 0.0, "%"}}),
};

INSTANTIATE_TEST_SUITE_P(Battery, CanOpenRow, ::testing::ValuesIn(kBatteryRows), row_name);

// ---- MPPT ------------------------------------------------------------------------------------
// spec: "MPPT CAN-format", COB-ID 0x4E6 + 8 * device_id, index "Don't Care". First two tables
// (subindex 0x00..0x06, 0x08..0x0F) on the base id; the third (duty cycles and channel map,
// subindex 0x01..0x05) on base + 1, as canopen.hpp documents. Voltages and currents have no
// resolution in the document and are raw counts; temperature is 1 degC/LSB, duty cycles 1 %/LSB.
std::vector<Row> mppt_rows(std::uint8_t device) {
  const std::uint16_t base = mppt_base(device);
  const std::string dev = "D" + std::to_string(device) + "_";
  auto row = [&](std::string label, std::uint16_t offset, std::uint8_t data0, std::uint16_t index, std::uint8_t sub,
                 std::initializer_list<std::uint8_t> value, std::vector<Expected> fields) {
    return Row{dev + label,
               static_cast<std::uint16_t>(base + offset),
               payload(data0, index, sub, value),
               Source::Mppt,
               device,
               std::move(fields)};
  };
  return {
      // base id, table 1
      row("00_voltage_output_int16_min", 0, 0x00, 0x0000, 0x00, {0x00, 0x80}, {{"voltage_output_raw", -32768, ""}}),
      row("00_voltage_output_int16_max", 0, 0x40, 0xFFFF, 0x00, {0xFF, 0x7F}, {{"voltage_output_raw", 32767, ""}}),
      row("00_voltage_output_4660", 0, 0x40, 0x2005, 0x00, {0x34, 0x12}, {{"voltage_output_raw", 4660, ""}}),
      row("01_current_output_int16_min", 0, 0x4B, 0x1234, 0x01, {0x00, 0x80}, {{"current_output_raw", -32768, ""}}),
      row("01_current_output_int16_max", 0, 0x4B, 0x1234, 0x01, {0xFF, 0x7F}, {{"current_output_raw", 32767, ""}}),
      row("02_voltage_out_sw_minus_1", 0, 0x43, 0x0000, 0x02, {0xFF, 0xFF}, {{"voltage_out_sw_raw", -1, ""}}),
      row("02_voltage_out_sw_int16_max", 0, 0x43, 0x0000, 0x02, {0xFF, 0x7F}, {{"voltage_out_sw_raw", 32767, ""}}),
      row("03_mppt_state_zero", 0, 0xFF, 0xFFFF, 0x03, {0x00}, {{"mppt_state", 0, ""}}),
      row("03_mppt_state_uint8_max", 0, 0xFF, 0xFFFF, 0x03, {0xFF}, {{"mppt_state", 255, ""}}),
      row("04_safety_enabled_false", 0, 0x00, 0x0001, 0x04, {0x00}, {{"safety_enabled", 0, ""}}),
      row("04_safety_enabled_true", 0, 0x00, 0x0001, 0x04, {0x01}, {{"safety_enabled", 1, ""}}),
      row("05_pwm_enabled_true", 0, 0x60, 0x0100, 0x05, {0x01}, {{"pwm_enabled", 1, ""}}),
      row("05_pwm_enabled_false", 0, 0x60, 0x0100, 0x05, {0x00}, {{"pwm_enabled", 0, ""}}),
      // A C bool: any non-zero byte is true.
      row("05_pwm_enabled_nonzero_is_true", 0, 0x60, 0x0100, 0x05, {0x02}, {{"pwm_enabled", 1, ""}}),
      row("06_temperature_int8_min", 0, 0x80, 0x2005, 0x06, {0x80}, {{"temperature", -128, "degC"}}),
      row("06_temperature_int8_max", 0, 0x80, 0x2005, 0x06, {0x7F}, {{"temperature", 127, "degC"}}),
      row("06_temperature_35", 0, 0x80, 0x2005, 0x06, {0x23}, {{"temperature", 35, "degC"}}),
      // base id, table 2
      row("08_voltage_panel_1_int16_min", 0, 0x01, 0x0000, 0x08, {0x00, 0x80}, {{"voltage_panel_1_raw", -32768, ""}}),
      row("09_current_panel_1_int16_max", 0, 0x01, 0x0000, 0x09, {0xFF, 0x7F}, {{"current_panel_1_raw", 32767, ""}}),
      row("0A_voltage_panel_2_one", 0, 0x01, 0x0000, 0x0A, {0x01, 0x00}, {{"voltage_panel_2_raw", 1, ""}}),
      row("0B_current_panel_2_minus_1", 0, 0x01, 0x0000, 0x0B, {0xFF, 0xFF}, {{"current_panel_2_raw", -1, ""}}),
      row("0C_voltage_panel_3_int16_min", 0, 0x01, 0x0000, 0x0C, {0x00, 0x80}, {{"voltage_panel_3_raw", -32768, ""}}),
      row("0D_current_panel_3_int16_max", 0, 0x01, 0x0000, 0x0D, {0xFF, 0x7F}, {{"current_panel_3_raw", 32767, ""}}),
      row("0E_voltage_panel_4_10000", 0, 0x01, 0x0000, 0x0E, {0x10, 0x27}, {{"voltage_panel_4_raw", 10000, ""}}),
      row("0F_current_panel_4_minus_10000", 0, 0x01, 0x0000, 0x0F, {0xF0, 0xD8}, {{"current_panel_4_raw", -10000, ""}}),
      // base + 1, table 3
      row("P1_01_duty_cycle_1_zero", 1, 0x00, 0x0000, 0x01, {0x00}, {{"duty_cycle_panel_1", 0, "%"}}),
      row("P1_02_duty_cycle_2_100", 1, 0x00, 0x2005, 0x02, {0x64}, {{"duty_cycle_panel_2", 100, "%"}}),
      row("P1_03_duty_cycle_3_uint8_max", 1, 0x00, 0xFFFF, 0x03, {0xFF}, {{"duty_cycle_panel_3", 255, "%"}}),
      row("P1_04_duty_cycle_4_50", 1, 0x00, 0x1234, 0x04, {0x32}, {{"duty_cycle_panel_4", 50, "%"}}),
      row("P1_05_channel_active_map", 1, 0x43, 0x0000, 0x05, {0x01, 0x00, 0x01, 0xFF},
          {{"channel_1_active", 1, ""},
           {"channel_2_active", 0, ""},
           {"channel_3_active", 1, ""},
           {"channel_4_active", 255, ""}}),
  };
}

INSTANTIATE_TEST_SUITE_P(MpptDevice0, CanOpenRow, ::testing::ValuesIn(mppt_rows(0)), row_name);
INSTANTIATE_TEST_SUITE_P(MpptDevice7, CanOpenRow, ::testing::ValuesIn(mppt_rows(7)), row_name);

TEST(CanOpenMppt, BaseIdFormulaGivesTheHexIdsOfTheDocument) {
  // "can_base_id = 1254 + (device_id * 8)", "needs to be converted to a hexadecimal value".
  EXPECT_EQ(mppt_base(0), 0x4E6);
  EXPECT_EQ(mppt_base(7), 0x51E);
  for (std::uint8_t d = 0; d < 8; ++d) {
    SCOPED_TRACE(static_cast<int>(d));
    for (std::uint16_t offset = 0; offset < 2; ++offset) {
      const auto r =
          canopen::decode(frame11(static_cast<std::uint32_t>(mppt_base(d) + offset), payload(0, 0, 0x03, {0x07})));
      if (offset == 0) {
        ASSERT_TRUE(r.ok()) << r.error().describe();
        EXPECT_EQ(r->device, d);
        EXPECT_EQ(r->source, Source::Mppt);
        EXPECT_EQ(r->fields[0].name, "mppt_state");
      } else {
        // The same subindex on base + 1 is the third table's: duty cycle panel 3.
        ASSERT_TRUE(r.ok()) << r.error().describe();
        EXPECT_EQ(r->device, d);
        EXPECT_EQ(r->fields[0].name, "duty_cycle_panel_3");
      }
      EXPECT_DOUBLE_EQ(r->fields[0].value, 7.0);
    }
  }
}

// ---- byte order --------------------------------------------------------------------------------
// The document never gives the byte order of Data[4..7]; canopen.hpp reads them
// little-endian, as CANopen does. Each value here would decode differently big-endian.
struct OrderCase {
  const char* what;
  std::uint16_t id;
  std::vector<std::uint8_t> data;
  double little_endian;  // the expected value
  double big_endian;     // what a big-endian reader would give
};

TEST(CanOpenByteOrder, ValuesAreLittleEndian) {
  const OrderCase cases[] = {
      // uint16 mV: 01 02 -> 0x0201 = 513 mV (big-endian 0x0102 = 258 mV)
      {"uint16 voltage", 0x302, payload(0, 0x2005, 0x01, {0x01, 0x02}), 0.513, 0.258},
      // int16 10 mA: 01 80 -> 0x8001 = -32767 -> -327.67 A (big-endian 0x0180 = 384 -> 3.84 A)
      {"int16 current", 0x302, payload(0, 0x2005, 0x02, {0x01, 0x80}), -327.67, 3.84},
      // uint32: 01 02 03 04 -> 0x04030201 (big-endian 0x01020304)
      {"uint32 BMS state", 0x402, payload(0, 0x2005, 0x0E, {0x01, 0x02, 0x03, 0x04}), 67305985.0, 16909060.0},
      // int16 raw: 00 01 -> 256 (big-endian 1)
      {"int16 MPPT raw", 0x4E6, payload(0, 0, 0x00, {0x00, 0x01}), 256.0, 1.0},
      // uint16 cell voltage: E8 03 -> 1000 mV (big-endian 0xE803 = 59395 mV)
      {"uint16 cell voltage", 0x482, payload(0, 0x2000, 0x01, {0xE8, 0x03}), 1.0, 59.395},
  };
  for (const auto& c : cases) {
    SCOPED_TRACE(c.what);
    const auto r = canopen::decode(frame11(c.id, c.data));
    ASSERT_TRUE(r.ok()) << r.error().describe();
    const Field& last = r->fields[r->field_count - 1u];
    EXPECT_DOUBLE_EQ(last.value, c.little_endian);
    EXPECT_NE(last.value, c.big_endian);
  }
}

TEST(CanOpenByteOrder, IndexIsLowByteFirst) {
  // Data[1] "Index Low", Data[2] "Index High": 05 20 is index 0x2005.
  const auto ok = canopen::decode(frame11(0x302, {0x00, 0x05, 0x20, 0x01, 0x00, 0x00}));
  ASSERT_TRUE(ok.ok()) << ok.error().describe();
  EXPECT_EQ(ok->index, 0x2005);
  // Swapped, it is index 0x0520, which 0x302 does not have.
  const auto swapped = canopen::decode(frame11(0x302, {0x00, 0x20, 0x05, 0x01, 0x00, 0x00}));
  ASSERT_FALSE(swapped.ok());
  EXPECT_EQ(swapped.error().kind, ErrorKind::UnknownIndex);
  EXPECT_EQ(swapped.error().index, 0x0520);
}

// ---- Data[0] -------------------------------------------------------------------------------
// The document calls Data[0] "Node-ID"; it is reported as command_byte and never checked.
TEST(CanOpenCommandByte, EveryValueIsReportedAndIgnored) {
  for (unsigned c = 0; c <= 0xFF; ++c) {
    SCOPED_TRACE(c);
    const auto cmd = static_cast<std::uint8_t>(c);
    const auto battery = canopen::decode(frame11(0x302, payload(cmd, 0x2005, 0x01, {0x39, 0x30})));
    ASSERT_TRUE(battery.ok());
    EXPECT_EQ(battery->command_byte, cmd);
    EXPECT_DOUBLE_EQ(battery->fields[0].value, 12.345);
    const auto mppt = canopen::decode(frame11(mppt_base(7), payload(cmd, 0, 0x06, {0xEC})));
    ASSERT_TRUE(mppt.ok());
    EXPECT_EQ(mppt->command_byte, cmd);
    EXPECT_DOUBLE_EQ(mppt->fields[0].value, -20.0);
  }
}

// ---- errors --------------------------------------------------------------------------------
struct ErrorCase {
  const char* what;
  CanFrame frame;
  ErrorKind kind;
  std::uint16_t index;    // checked for UnknownIndex / UnknownSubindex
  std::uint8_t subindex;  // checked for UnknownSubindex
  std::uint8_t needed;    // checked for TooShort
};

CanFrame remote(std::uint32_t id, std::uint8_t length) {
  CanFrame f = frame11(id, {});
  f.remote = true;
  f.length = length;
  return f;
}

CanFrame extended(std::uint32_t id, const std::vector<std::uint8_t>& bytes) {
  CanFrame f = frame11(id, bytes);
  f.extended = true;
  return f;
}

void expect_error(const ErrorCase& c) {
  SCOPED_TRACE(c.what);
  const auto r = canopen::decode(c.frame);
  ASSERT_FALSE(r.ok()) << "decoded a value";
  const Error& e = r.error();
  EXPECT_EQ(e.kind, c.kind) << e.describe();
  EXPECT_EQ(std::uint32_t{e.cob_id}, c.frame.id & 0xFFFFu);
  EXPECT_EQ(e.length, c.frame.length);
  if (c.kind == ErrorKind::UnknownIndex || c.kind == ErrorKind::UnknownSubindex) {
    EXPECT_EQ(e.index, c.index);
  }
  if (c.kind == ErrorKind::UnknownSubindex) {
    EXPECT_EQ(e.subindex, c.subindex);
  }
  if (c.kind == ErrorKind::TooShort) {
    EXPECT_EQ(e.needed, c.needed);
  }
  EXPECT_FALSE(e.describe().empty());
}

// spec "Battery (MG) CAN-format": 0x302 and 0x402 use index 0x2005, 0x482 index 0x2000;
// subindex 0x06 and 0x0A are blank rows. "MPPT CAN-format": subindex 0x07 is in neither of the
// first two tables; the third has 0x01..0x05 only.
TEST(CanOpenErrors, UnknownIndexAndSubindex) {
  const ErrorCase cases[] = {
      {"302 index 2006", frame11(0x302, payload(0, 0x2006, 0x01, {0, 0})), ErrorKind::UnknownIndex, 0x2006, 0, 0},
      {"302 index 2000", frame11(0x302, payload(0, 0x2000, 0x01, {0, 0})), ErrorKind::UnknownIndex, 0x2000, 0, 0},
      {"402 index 0000", frame11(0x402, payload(0, 0x0000, 0x09, {0})), ErrorKind::UnknownIndex, 0x0000, 0, 0},
      {"482 index 2005", frame11(0x482, payload(0, 0x2005, 0x01, {0, 0})), ErrorKind::UnknownIndex, 0x2005, 0, 0},
      {"302 sub 00", frame11(0x302, payload(0, 0x2005, 0x00, {0, 0})), ErrorKind::UnknownSubindex, 0x2005, 0x00, 0},
      {"302 sub 06 (blank row)", frame11(0x302, payload(0, 0x2005, 0x06, {0, 0})), ErrorKind::UnknownSubindex, 0x2005,
       0x06, 0},
      {"302 sub 08", frame11(0x302, payload(0, 0x2005, 0x08, {0, 0})), ErrorKind::UnknownSubindex, 0x2005, 0x08, 0},
      {"302 sub 09 (a 0x402 row)", frame11(0x302, payload(0, 0x2005, 0x09, {0})), ErrorKind::UnknownSubindex, 0x2005,
       0x09, 0},
      {"402 sub 01 (a 0x302 row)", frame11(0x402, payload(0, 0x2005, 0x01, {0, 0})), ErrorKind::UnknownSubindex, 0x2005,
       0x01, 0},
      {"402 sub 0A (blank row)", frame11(0x402, payload(0, 0x2005, 0x0A, {0})), ErrorKind::UnknownSubindex, 0x2005,
       0x0A, 0},
      {"402 sub 10", frame11(0x402, payload(0, 0x2005, 0x10, {0, 0, 0, 0})), ErrorKind::UnknownSubindex, 0x2005, 0x10,
       0},
      {"MPPT0 sub 07", frame11(mppt_base(0), payload(0, 0x1234, 0x07, {0, 0})), ErrorKind::UnknownSubindex, 0x1234,
       0x07, 0},
      {"MPPT7 sub 10", frame11(mppt_base(7), payload(0, 0x0000, 0x10, {0, 0})), ErrorKind::UnknownSubindex, 0x0000,
       0x10, 0},
      {"MPPT0+1 sub 00", frame11(mppt_base(0) + 1u, payload(0, 0x0000, 0x00, {0, 0, 0, 0})), ErrorKind::UnknownSubindex,
       0x0000, 0x00, 0},
      {"MPPT7+1 sub 06", frame11(mppt_base(7) + 1u, payload(0, 0xFFFF, 0x06, {0, 0, 0, 0})), ErrorKind::UnknownSubindex,
       0xFFFF, 0x06, 0},
  };
  for (const auto& c : cases) expect_error(c);
}

// A frame must hold the 4 header bytes and the value its row's type needs: 1 byte for
// (u)int8/bool, 2 for (u)int16, 4 for uint32 and 4x uint8. Without a value byte at all the
// decoder cannot even pick the row, and asks for the 5 bytes of the smallest one.
TEST(CanOpenErrors, TooShortFrames) {
  const ErrorCase cases[] = {
      {"302 length 0", frame11(0x302, {}), ErrorKind::TooShort, 0, 0, 5},
      {"302 length 1", frame11(0x302, {0x00}), ErrorKind::TooShort, 0, 0, 5},
      {"302 length 4 (header only)", frame11(0x302, payload(0, 0x2005, 0x01, {})), ErrorKind::TooShort, 0, 0, 5},
      {"302 uint16 in 1 byte", frame11(0x302, payload(0, 0x2005, 0x01, {0x39})), ErrorKind::TooShort, 0, 0, 6},
      {"302 int16 in 1 byte", frame11(0x302, payload(0, 0x2005, 0x02, {0x39})), ErrorKind::TooShort, 0, 0, 6},
      {"402 uint16 in 1 byte", frame11(0x402, payload(0, 0x2005, 0x0C, {0x10})), ErrorKind::TooShort, 0, 0, 6},
      {"402 uint32 in 3 bytes", frame11(0x402, payload(0, 0x2005, 0x0E, {1, 2, 3})), ErrorKind::TooShort, 0, 0, 8},
      {"402 4x uint8 in 3 bytes", frame11(0x402, payload(0, 0x2005, 0x0F, {1, 2, 3})), ErrorKind::TooShort, 0, 0, 8},
      {"482 uint16 in 1 byte", frame11(0x482, payload(0, 0x2000, 0x01, {0x7B})), ErrorKind::TooShort, 0, 0, 6},
      {"202 length 4", frame11(0x202, payload(0, 0, 0, {})), ErrorKind::TooShort, 0, 0, 5},
      {"MPPT0 length 3", frame11(mppt_base(0), {0, 0, 0}), ErrorKind::TooShort, 0, 0, 5},
      {"MPPT0 int16 in 1 byte", frame11(mppt_base(0), payload(0, 0, 0x00, {0xFF})), ErrorKind::TooShort, 0, 0, 6},
      {"MPPT7+1 4x uint8 in 2 bytes", frame11(mppt_base(7) + 1u, payload(0, 0, 0x05, {1, 0})), ErrorKind::TooShort, 0,
       0, 8},
  };
  for (const auto& c : cases) expect_error(c);
}

// spec "CANopen format": a frame with RTR set carries no data to decode.
TEST(CanOpenErrors, RemoteFrames) {
  const ErrorCase cases[] = {
      {"302 RTR len 0", remote(0x302, 0), ErrorKind::RemoteFrame, 0, 0, 0},
      {"302 RTR len 8", remote(0x302, 8), ErrorKind::RemoteFrame, 0, 0, 0},
      {"202 RTR", remote(0x202, 5), ErrorKind::RemoteFrame, 0, 0, 0},
      {"402 RTR", remote(0x402, 8), ErrorKind::RemoteFrame, 0, 0, 0},
      {"482 RTR", remote(0x482, 6), ErrorKind::RemoteFrame, 0, 0, 0},
      {"MPPT0 RTR", remote(mppt_base(0), 6), ErrorKind::RemoteFrame, 0, 0, 0},
      {"MPPT7+1 RTR", remote(mppt_base(7) + 1u, 8), ErrorKind::RemoteFrame, 0, 0, 0},
  };
  for (const auto& c : cases) expect_error(c);
}

// spec "CANopen format": "A CAN-frame consists of an 11-bit identifier". The same number as a
// 29-bit id is someone else's frame.
TEST(CanOpenErrors, ExtendedIdsAreNotOurs) {
  const std::uint32_t ids[] = {0x202, 0x302, 0x402, 0x482, mppt_base(0), mppt_base(7) + 1u, 0x1E000302};
  for (std::uint32_t id : ids) {
    SCOPED_TRACE(id);
    EXPECT_FALSE(is_canopen_id(id, true));
    expect_error({"extended", extended(id, payload(0, 0x2005, 0x01, {0x39, 0x30})), ErrorKind::NotOurs, 0, 0, 0});
  }
}

TEST(CanOpenIds, IdsNotInTheTables) {
  // Neighbours of every table id, the gaps inside each MPPT block of 8 (base + 2 .. base + 7),
  // the first id after device 7's block, and the ends of the 11-bit range.
  const std::uint32_t ids[] = {0x000, 0x001, 0x182, 0x201, 0x203, 0x282, 0x301, 0x303, 0x401,
                               0x403, 0x481, 0x483, 0x4E5, 0x4E8, 0x4EB, 0x4ED, 0x4F0, 0x518,
                               0x520, 0x525, 0x526, 0x527, 0x52E, 0x602, 0x7FF};
  for (std::uint32_t id : ids) {
    SCOPED_TRACE(id);
    EXPECT_FALSE(is_canopen_id(id, false));
    expect_error(
        {"not in the table", frame11(id, payload(0, 0x2005, 0x01, {0x39, 0x30})), ErrorKind::NotOurs, 0, 0, 0});
  }
}

TEST(CanOpenIds, EveryTableIdIsRecognised) {
  // spec: battery Node-IDs 0x302, 0x402, 0x482, 0x202; MPPT 0x4E6 + 8 * id for id 0..7 (and
  // base + 1 for the third table).
  for (std::uint32_t id : {0x202u, 0x302u, 0x402u, 0x482u}) EXPECT_TRUE(is_canopen_id(id, false)) << id;
  for (unsigned d = 0; d < 8; ++d) {
    EXPECT_TRUE(is_canopen_id(mppt_base(d), false)) << d;
    EXPECT_TRUE(is_canopen_id(mppt_base(d) + 1u, false)) << d;
  }
}

TEST(CanOpenErrors, DescribeNamesTheFrame) {
  const auto unknown = canopen::decode(frame11(0x402, payload(0, 0x2005, 0x0A, {0})));
  ASSERT_FALSE(unknown.ok());
  const std::string text = unknown.error().describe();
  EXPECT_NE(text.find("402"), std::string::npos) << text;
  EXPECT_NE(text.find("0x0A"), std::string::npos) << text;
  const auto short_frame = canopen::decode(frame11(0x402, payload(0, 0x2005, 0x0E, {1, 2, 3})));
  ASSERT_FALSE(short_frame.ok());
  const std::string s = short_frame.error().describe();
  EXPECT_NE(s.find("7"), std::string::npos) << s;
  EXPECT_NE(s.find("8"), std::string::npos) << s;
}

}  // namespace
}  // namespace pmu::codec::canopen::decode_test
