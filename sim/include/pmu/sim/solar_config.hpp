#pragma once
// Configuration of the simulated solar-boat devices (spec/solar-boat-canopen-battery-mppt.txt):
// an MG battery's BMS (BatterySimConfig), MPPTs (MpptSimConfig), the world they share on one
// bus (SolarWorld: sun, load) and the faults a test injects (CanOpenFaults). Plain data;
// SolarPlant (solar_plant.hpp) owns the physics, BatteryModel and MpptModel the frames.

#include <chrono>
#include <cstdint>
#include <vector>

namespace pmu::sim {

struct BatterySimConfig {
  std::uint8_t node = 2;  // CANopen node id 1..127; 2 gives the document's ids (0x302, ...)
  // Every value of the battery's table is sent once per period, spread evenly over it.
  std::chrono::milliseconds period{1000};
  // Cells in series, 1..15: each is sent on 0x482 with its number as subindex. Li-ion cells
  // (3.0..4.2 V), so 15 is the most whose full pack voltage fits 0x302's uint16 mV.
  int cells = 12;
  double capacity_ah = 20.0;
  double initial_soc = 0.8;        // 0..1
  double cell_resistance = 0.002;  // ohm per cell: the pack's voltage drop under current
  // Empty: each cell's voltage follows the state of charge and the current. Otherwise one
  // value per cell (cell 1 first, `cells` of them), read as given whatever the charge and
  // current: a bench setting for a pack the curve cannot produce (an unbalanced or
  // over-charged cell), which the BMS frames must then show as set.
  std::vector<double> cell_voltages;
};

struct MpptSimConfig {
  std::uint8_t device = 0;  // 0..7, set on the PCB: COB-ID 0x4E6 + 8 * device
  std::chrono::milliseconds period{1000};
  int panels = 4;           // panels connected to channels 1..panels (0..4)
  double panel_vmp = 30.0;  // V at the maximum power point at 1000 W/m2
  double panel_imp = 8.0;   // A at the maximum power point at 1000 W/m2
};

// What the batteries and MPPTs on one bus share. The irradiance follows a slow sine
// (mean +- swing over `irradiance_cycle`) unless a test fixes it (SolarPlant::set_irradiance).
struct SolarWorld {
  double irradiance_mean = 600.0;   // W/m2
  double irradiance_swing = 300.0;  // W/m2
  std::chrono::seconds irradiance_cycle{600};
  double load_current = 5.0;          // A drawn from the batteries (shared equally)
  double ambient_temperature = 25.0;  // degC
};

// How the garble fault spoils each frame a device sends; every spoiled frame fails to
// decode with codec::canopen::decode.
enum class Garble : std::uint8_t {
  None,
  WrongLength,      // one byte too short to hold the value (TooShort)
  UnknownSubindex,  // a subindex the document leaves blank (UnknownSubindex); where the
                    // subindex selects nothing (0x482 cells, 0x202) an unknown index or a
                    // short frame instead
};

struct CanOpenFaults {
  // Off the bus: nothing is sent; the device keeps running (the battery's charge integrates)
  // and resumes its schedule without a catch-up burst.
  bool silent = false;
  Garble garble = Garble::None;
};

// What happened to the frames a battery or MPPT model was due to send.
struct CanOpenCounters {
  std::uint64_t frames_out = 0;     // handed to the sink (garbled ones included)
  std::uint64_t suppressed = 0;     // not sent: silence fault
  std::uint64_t garbled = 0;        // sent spoiled: garble fault
  std::uint64_t encode_errors = 0;  // a value the codec refused (a model bug: values are clamped)
};

}  // namespace pmu::sim
