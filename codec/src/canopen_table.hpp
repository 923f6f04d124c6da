#pragma once
// The rows of spec/solar-boat-canopen-battery-mppt.txt as data, private to the codec: the
// decoder (canopen.cpp) and the device-side encoders (canopen_encode.cpp) read the same rows,
// so a value can only be written the way it is read.

#include <cstdint>
#include <iterator>
#include <string_view>

namespace pmu::codec::canopen {

enum class Type : std::uint8_t { U8, I8, U16, I16, U32, Bool, U8x4 };

constexpr std::uint8_t size_of(Type t) noexcept {
  switch (t) {
    case Type::U8:
    case Type::I8:
    case Type::Bool: return 1;
    case Type::U16:
    case Type::I16: return 2;
    case Type::U32:
    case Type::U8x4: return 4;
  }
  return 4;
}

inline constexpr std::int32_t kAnyIndex = -1;
inline constexpr std::int32_t kAnySubindex = -1;

struct Entry {
  std::uint16_t cob_offset;  // battery: the COB-ID; MPPT: offset from the device base id
  std::int32_t index;        // kAnyIndex: "Don't Care" in the document
  std::int32_t subindex;     // kAnySubindex: the subindex is a number (cell), not a selector
  std::string_view name;
  Type type;
  double divisor;
  std::string_view unit;
};

// Battery (MG) table.
inline constexpr Entry kBattery[] = {
    {0x302, 0x2005, 0x01, "voltage", Type::U16, 1000, "V"},
    {0x302, 0x2005, 0x02, "current", Type::I16, 100, "A"},
    {0x302, 0x2005, 0x03, "current_discharge", Type::I16, 100, "A"},
    {0x302, 0x2005, 0x04, "current_charge", Type::I16, 100, "A"},
    {0x302, 0x2005, 0x05, "state_of_charge", Type::I8, 1, "%"},
    {0x302, 0x2005, 0x07, "time_to_go", Type::U16, 1, "min"},
    {0x402, 0x2005, 0x09, "cell_temperature_high", Type::I8, 1, "degC"},
    {0x402, 0x2005, 0x0B, "cell_temperature_low", Type::I8, 1, "degC"},
    {0x402, 0x2005, 0x0C, "cell_voltage_high", Type::U16, 1000, "V"},
    {0x402, 0x2005, 0x0D, "cell_voltage_low", Type::U16, 1000, "V"},
    {0x402, 0x2005, 0x0E, "bms_state", Type::U32, 1, ""},
    {0x402, 0x2005, 0x0F, "temperature_collection", Type::U8x4, 1, "degC"},
    {0x482, 0x2000, kAnySubindex, "cell_voltage", Type::U16, 1000, "V"},
    {0x202, kAnyIndex, kAnySubindex, "power_level", Type::U8, 1, "%"},
};

// MPPT table, offsets from 0x4E6 + 8 * device.
inline constexpr Entry kMppt[] = {
    {0, kAnyIndex, 0x00, "voltage_output_raw", Type::I16, 1, ""},
    {0, kAnyIndex, 0x01, "current_output_raw", Type::I16, 1, ""},
    {0, kAnyIndex, 0x02, "voltage_out_sw_raw", Type::I16, 1, ""},
    {0, kAnyIndex, 0x03, "mppt_state", Type::U8, 1, ""},
    {0, kAnyIndex, 0x04, "safety_enabled", Type::Bool, 1, ""},
    {0, kAnyIndex, 0x05, "pwm_enabled", Type::Bool, 1, ""},
    {0, kAnyIndex, 0x06, "temperature", Type::I8, 1, "degC"},
    {0, kAnyIndex, 0x08, "voltage_panel_1_raw", Type::I16, 1, ""},
    {0, kAnyIndex, 0x09, "current_panel_1_raw", Type::I16, 1, ""},
    {0, kAnyIndex, 0x0A, "voltage_panel_2_raw", Type::I16, 1, ""},
    {0, kAnyIndex, 0x0B, "current_panel_2_raw", Type::I16, 1, ""},
    {0, kAnyIndex, 0x0C, "voltage_panel_3_raw", Type::I16, 1, ""},
    {0, kAnyIndex, 0x0D, "current_panel_3_raw", Type::I16, 1, ""},
    {0, kAnyIndex, 0x0E, "voltage_panel_4_raw", Type::I16, 1, ""},
    {0, kAnyIndex, 0x0F, "current_panel_4_raw", Type::I16, 1, ""},
    {1, kAnyIndex, 0x01, "duty_cycle_panel_1", Type::U8, 1, "%"},
    {1, kAnyIndex, 0x02, "duty_cycle_panel_2", Type::U8, 1, "%"},
    {1, kAnyIndex, 0x03, "duty_cycle_panel_3", Type::U8, 1, "%"},
    {1, kAnyIndex, 0x04, "duty_cycle_panel_4", Type::U8, 1, "%"},
    {1, kAnyIndex, 0x05, "channel_active_map", Type::U8x4, 1, ""},
};

inline constexpr std::uint8_t kHeader = 4;  // Data[0] command byte, Data[1..2] index, Data[3] subindex

}  // namespace pmu::codec::canopen
