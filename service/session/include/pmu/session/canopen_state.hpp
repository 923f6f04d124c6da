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
#include "pmu/idl_tables/canopen_values.hpp"

namespace pmu::service {

// The tables of values (names, scales, units in IDL order): pmu/idl_tables/canopen_values.hpp.

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
