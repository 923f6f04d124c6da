#pragma once
// `interface: sim` (and --bus sim): the bus's configured devices as simulated units on an
// in-process bus shared with the service, so the whole daemon runs with no CAN hardware.
// Start-up only: sim::BusRunner refuses a device the model cannot be (std::invalid_argument).

#include <memory>

#include "pmu/config/config.hpp"
#include "pmu/sim/bus_runner.hpp"
#include "pmu/transport/can_bus.hpp"
#include "pmu/transport/clock.hpp"
#include "pmu/transport/sim_bus.hpp"

namespace pmu::service {

// Destroyed in reverse order: the network outlives both of its ends.
struct SimulatedBus {
  std::unique_ptr<transport::SimulatedNetwork> network;
  // Not started: the caller starts it with the bus workers and stops it after them.
  std::unique_ptr<sim::BusRunner> simulator;
  std::unique_ptr<transport::CanBus> service_end;  // the bus worker's end
};

// One simulated PMU per configured address (address 1 when the bus only discovers), each
// streaming what the config expects with its engine running, plus the bus's batteries and
// MPPTs on one solar plant; each device's `sim:` settings (sim_settings.hpp) change its
// world and faults from power-up. `clock` must outlive the result.
SimulatedBus make_simulated_bus(const BusConfig& bus, const transport::Clock& clock);

}  // namespace pmu::service
