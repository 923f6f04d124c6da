#pragma once
// The `sim:` mapping of a device on an `interface: sim` bus (docs/interface.md section 4.4):
// the world the built-in simulator puts around that device, so a demo or a test can start a
// service against an engine that will not start, a hot PMU or a silent unit. Plain data:
// this room does not see sim/ (docs/design.md, Folders); service/app/src/simulated_bus.cpp
// turns these into the models' Plant and faults. An unset value leaves the model's own.

#include <chrono>
#include <cstdint>
#include <map>
#include <optional>
#include <vector>

#include "pmu/codec/firmware.hpp"
#include "pmu/codec/parameters.hpp"

namespace pmu::service {

struct PmuSimSettings {
  bool engine_running = true;  // engine: running|stopped at power-up
  // engine_starts_after: how long cranking lasts before the engine fires; `never` (a flooded
  // engine: only CT or an engine stop ends the cranking) sets engine_never_starts.
  std::optional<std::chrono::milliseconds> engine_starts_after;
  bool engine_never_starts = false;
  std::optional<double> internal_temperature;  // degC
  std::optional<double> battery_a_voltage;     // V
  std::optional<double> battery_b_voltage;     // V
  std::optional<bool> starter_ready;
  std::optional<bool> soa_shutdown;
  std::optional<bool> payload_shed;
  bool silent = false;                             // off the bus: answers and streams nothing
  std::optional<codec::FirmwareVersion> firmware;  // the firmware it behaves as
  std::optional<std::uint16_t> serial;             // its serial number
  std::optional<codec::Parameter> ignores_set;     // a stored parameter its memory does not take
};

// How a battery's or MPPT's frames are spoiled, each one failing to decode.
enum class SimGarble : unsigned char { None, WrongLength, UnknownSubindex };

struct BatterySimSettings {
  std::optional<double> state_of_charge;  // % at power-up
  std::optional<int> cells;
  // V, cell 1 first, as many as `cells` (which it sets when `cells` is not given); empty:
  // the cells follow the state of charge.
  std::vector<double> cell_voltages;
  bool silent = false;
  SimGarble garble = SimGarble::None;
};

struct MpptSimSettings {
  std::optional<int> panels;  // connected to channels 1..panels
  bool silent = false;
  SimGarble garble = SimGarble::None;
};

// The `sim:` mappings of one bus's devices, by the key each device has on the bus. A device
// without one is not in these maps.
struct BusSimSettings {
  std::map<std::uint16_t, PmuSimSettings> pmus;          // by address
  std::map<std::uint8_t, BatterySimSettings> batteries;  // by node
  std::map<std::uint8_t, MpptSimSettings> mppts;         // by device
};

}  // namespace pmu::service
