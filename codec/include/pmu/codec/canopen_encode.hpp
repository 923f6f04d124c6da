#pragma once
// Device side of the solar-boat battery (MG) and MPPT frames
// (spec/solar-boat-canopen-battery-mppt.txt): the frames a BMS or an MPPT sends, for the
// simulator. The service only reads these devices (canopen.hpp); nothing here is a command.
//
// Each encoder writes one value of the document's tables the way codec::canopen::decode
// reads it (the same rows, codec/src/canopen_table.hpp), so every frame built here decodes
// back to the same name, value and unit. The readings canopen.hpp documents apply:
//  * COB-ID: function code + node id, as the document's "Function code | Node ID" layout
//    says. The document's ids (0x202, 0x302, 0x402, 0x482) are those of node 2
//    (kBatteryNode); other nodes 1..127 are encoded the same way, but decode() knows only
//    the document's ids. MPPT: 0x4E6 + 8 * device, the third table on base + 1.
//  * Data[0]: the CANopen expedited upload response for the value's size (0x4F one byte,
//    0x4B two, 0x43 four), what a CANopen node puts there; decode() does not check it.
//  * Index and subindex of the row; where the document says "Don't Care" we write 0.
//  * The value little-endian in Data[4..], rounded to the row's resolution; unused bytes 0
//    and the frame always 8 bytes long, as a CANopen SDO frame is.
//
// Refusals (a Result, never an exception, never a frame): NaN or infinity (NotANumber); a
// value whose rounded raw count does not fit the row's type (OutOfRange, with the range in
// the row's unit); a node outside 1..127, an MPPT device outside 0..7 (OutOfRange on
// "node" / "device"). MPPT voltages and currents are raw counts (the document gives no
// resolution): the caller chooses its own scale.
//
//   encode_battery(BatteryValue::Voltage, 48.123)    -> 302#4B052001FBBB0000  (48123 mV)
//   encode_cell_voltage(3, 3.7)                      -> 482#4B002003740E0000  (cell 3, 3700 mV)
//   encode_mppt(1, MpptValue::DutyCyclePanel2, 40)   -> 4EF#4F00000228000000  (base 0x4EE + 1)
// (canopen_encode_test checks these three.)

#include <array>
#include <cstdint>
#include <string_view>

#include "pmu/codec/can_frame.hpp"
#include "pmu/codec/encode.hpp"
#include "pmu/codec/result.hpp"

namespace pmu::codec::canopen {

// The node whose ids the document lists (0x202, 0x302, 0x402, 0x482).
inline constexpr std::uint8_t kBatteryNode = 2;
inline constexpr std::uint8_t kMaxNode = 127;  // 7-bit CANopen node id

// The battery's single values, named as decode() names them. The cell voltages (0x482) and
// the temperature collection (0x402/0x0F) carry more than a value and have their own encoders.
enum class BatteryValue : std::uint8_t {
  Voltage,              // 0x302/0x01 V, uint16 1 mV
  Current,              // 0x302/0x02 A, int16 10 mA
  CurrentDischarge,     // 0x302/0x03 A, int16 10 mA
  CurrentCharge,        // 0x302/0x04 A, int16 10 mA
  StateOfCharge,        // 0x302/0x05 %, int8
  TimeToGo,             // 0x302/0x07 min, uint16
  CellTemperatureHigh,  // 0x402/0x09 degC, int8
  CellTemperatureLow,   // 0x402/0x0B degC, int8
  CellVoltageHigh,      // 0x402/0x0C V, uint16 1 mV
  CellVoltageLow,       // 0x402/0x0D V, uint16 1 mV
  BmsState,             // 0x402/0x0E uint32, no unit
  PowerLevel,           // 0x202 %, uint8 in Data[4]
};
inline constexpr std::uint8_t kBatteryValueCount = 12;

// The MPPT's single values, in the document's order; the first fifteen on the device's base
// id, the duty cycles on base + 1. The channel map has its own encoder.
enum class MpptValue : std::uint8_t {
  VoltageOutputRaw,
  CurrentOutputRaw,
  VoltageOutSwRaw,
  MpptState,
  SafetyEnabled,
  PwmEnabled,
  Temperature,
  VoltagePanel1Raw,
  CurrentPanel1Raw,
  VoltagePanel2Raw,
  CurrentPanel2Raw,
  VoltagePanel3Raw,
  CurrentPanel3Raw,
  VoltagePanel4Raw,
  CurrentPanel4Raw,
  DutyCyclePanel1,
  DutyCyclePanel2,
  DutyCyclePanel3,
  DutyCyclePanel4,
};
inline constexpr std::uint8_t kMpptValueCount = 19;

// The name decode() gives the value ("voltage", "duty_cycle_panel_2", ...).
std::string_view name_of(BatteryValue v) noexcept;
std::string_view name_of(MpptValue v) noexcept;

Encoded encode_battery(BatteryValue v, double value, std::uint8_t node = kBatteryNode) noexcept;
// 0x482, index 0x2000, subindex = cell number; volts.
Encoded encode_cell_voltage(std::uint8_t cell, double volts, std::uint8_t node = kBatteryNode) noexcept;
// 0x402/0x0F: four uint8 sensors, degC (0..255).
Encoded encode_temperature_collection(const std::array<double, 4>& celsius, std::uint8_t node = kBatteryNode) noexcept;

Encoded encode_mppt(std::uint8_t device, MpptValue v, double value) noexcept;
// base + 1, subindex 0x05: one uint8 per channel (1 active, 0 not; the document says no more).
Encoded encode_channel_active_map(std::uint8_t device, const std::array<std::uint8_t, 4>& channels) noexcept;

}  // namespace pmu::codec::canopen
