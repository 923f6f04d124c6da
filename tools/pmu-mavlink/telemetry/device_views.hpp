#pragma once
// What pmu-mavlink last read of one PMU and of one BMS: the latest sample of each contract
// topic that feeds a MAVLink message (interface.md 1.2, 1.4, 1.8), and whether the service
// says the device is ONLINE (pmu/health). Plain data: the DDS readers fill it, the mapping
// (battery_status.hpp, generator_status.hpp) reads it, tests build it by hand.
#include <optional>

#include "pmu/idl/canopen.h"
#include "pmu/idl/energy.h"
#include "pmu/idl/telemetry.h"

namespace pmu::mavlink_bridge {

struct PmuView {
  std::optional<pmu::v5::Voltages> voltages;
  std::optional<pmu::v5::Currents> currents;
  std::optional<pmu::v5::BatteryEnergy> battery_energy;
  std::optional<pmu::v5::Temperatures> temperatures;
  std::optional<pmu::v5::Status> status;
  std::optional<pmu::v5::Energy> energy;
  // pmu/health ONLINE. Anything else (UNKNOWN, STALE, OFFLINE, no health sample) makes every
  // measured field "not provided": a value kept from before is not shown as live
  // (docs/safety.md H7).
  bool online = false;
};

struct BmsView {
  std::optional<pmu::v5::Battery> battery;
  std::optional<pmu::v5::BatteryCells> cells;
  std::optional<pmu::v5::BmsEnergy> energy;
  bool online = false;  // as PmuView::online, from the battery's pmu/health instance
};

}  // namespace pmu::mavlink_bridge
