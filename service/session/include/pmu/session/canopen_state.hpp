#pragma once
// What the service knows of one battery (MG BMS) or MPPT, assembled from CANopen frames that
// each carry one value (spec/solar-boat-canopen-battery-mppt.txt, codec/canopen.hpp).
//
// Each device's values sit in a fixed table of slots in the contract's order (the order of
// the IDL fields, interface.md section 1.4). A slot holds the value in the contract's unit,
// or NaN while it has not been received since the session started or since the device came
// back after OFFLINE; "not received" is never 0. The DDS side turns NaN of an integer or
// flag field into the `received` bit mask the contract defines.
//
// The codec names each value (`voltage`, `time_to_go`, `voltage_output_raw`, ...); those
// names are the contract's field names, so the codec's name picks the slot. Units follow the
// contract: the document's minutes (time to go) become seconds; everything else keeps the
// codec's unit (V, A, %, degC, raw counts).

#include <array>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <limits>
#include <optional>
#include <string_view>

#include "pmu/codec/canopen.hpp"

namespace pmu::service {

struct CanOpenValue {
  std::string_view name;  // the contract's field name = the codec's value name
  double scale;           // codec value x scale = contract value
  std::string_view unit;  // the contract's unit ("" for raw counts, states and flags)
};

// pmu::v5::Battery's values, in IDL order.
inline constexpr CanOpenValue kBatteryValues[] = {
    {"voltage", 1, "V"},
    {"current", 1, "A"},
    {"current_discharge", 1, "A"},
    {"current_charge", 1, "A"},
    {"state_of_charge", 1, "%"},
    {"time_to_go", 60, "s"},  // the document's minutes, in the contract's seconds
    {"cell_temperature_high", 1, "degC"},
    {"cell_temperature_low", 1, "degC"},
    {"cell_voltage_high", 1, "V"},
    {"cell_voltage_low", 1, "V"},
    {"bms_state", 1, ""},
    {"temperature_1", 1, "degC"},
    {"temperature_2", 1, "degC"},
    {"temperature_3", 1, "degC"},
    {"temperature_4", 1, "degC"},
    {"power_level", 1, "%"},
};
inline constexpr std::size_t kBatteryValueCount = std::size(kBatteryValues);

// pmu::v5::Mppt's values, in IDL order. Voltages and currents are raw counts: the document gives
// them no resolution.
inline constexpr CanOpenValue kMpptValues[] = {
    {"voltage_output_raw", 1, ""},
    {"current_output_raw", 1, ""},
    {"voltage_out_sw_raw", 1, ""},
    {"mppt_state", 1, ""},
    {"safety_enabled", 1, ""},
    {"pwm_enabled", 1, ""},
    {"temperature", 1, "degC"},
    {"voltage_panel_1_raw", 1, ""},
    {"current_panel_1_raw", 1, ""},
    {"duty_cycle_panel_1", 1, "%"},
    {"channel_1_active", 1, ""},
    {"voltage_panel_2_raw", 1, ""},
    {"current_panel_2_raw", 1, ""},
    {"duty_cycle_panel_2", 1, "%"},
    {"channel_2_active", 1, ""},
    {"voltage_panel_3_raw", 1, ""},
    {"current_panel_3_raw", 1, ""},
    {"duty_cycle_panel_3", 1, "%"},
    {"channel_3_active", 1, ""},
    {"voltage_panel_4_raw", 1, ""},
    {"current_panel_4_raw", 1, ""},
    {"duty_cycle_panel_4", 1, "%"},
    {"channel_4_active", 1, ""},
};
inline constexpr std::size_t kMpptValueCount = std::size(kMpptValues);

// Subindex 0..255 of 0x482 is the cell number.
inline constexpr std::size_t kMaxCells = 256;

template <std::size_t N>
struct CanOpenValues {
  static constexpr double kNotReceived = std::numeric_limits<double>::quiet_NaN();
  std::array<double, N> values = filled();

  bool received(std::size_t slot) const noexcept { return !std::isnan(values[slot]); }
  // Bit i: slot i was received.
  std::uint32_t received_mask() const noexcept {
    std::uint32_t m = 0;
    for (std::size_t i = 0; i < N && i < 32; ++i)
      if (received(i)) m |= std::uint32_t{1} << i;
    return m;
  }
  void clear() noexcept { values = filled(); }

 private:
  static constexpr std::array<double, N> filled() {
    std::array<double, N> a{};
    for (auto& v : a) v = kNotReceived;
    return a;
  }
};

using BatteryState = CanOpenValues<kBatteryValueCount>;
using MpptState = CanOpenValues<kMpptValueCount>;

// Cell voltages (V) by cell number; NaN: not received.
struct BatteryCellsState {
  std::array<double, kMaxCells> volts = CanOpenValues<kMaxCells>{}.values;
  void clear() noexcept { volts = CanOpenValues<kMaxCells>{}.values; }
};

// The slot of a codec value name in a table; nullopt when the table has no such value.
std::optional<std::size_t> battery_slot(std::string_view name) noexcept;
std::optional<std::size_t> mppt_slot(std::string_view name) noexcept;

// What a decoded frame changed. Pure: the session decides what to publish.
struct Applied {
  bool battery = false;  // pmu::v5::Battery's values
  bool cells = false;    // pmu::v5::BatteryCells
  bool mppt = false;     // pmu::v5::Mppt
};
Applied apply(const codec::canopen::CanOpenMessage& m, BatteryState& battery, BatteryCellsState& cells) noexcept;
Applied apply(const codec::canopen::CanOpenMessage& m, MpptState& mppt) noexcept;

}  // namespace pmu::service
