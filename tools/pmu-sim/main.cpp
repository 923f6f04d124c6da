// pmu-sim IFACE [--address N] [--firmware X.Y] [--serial N] [--battery NODE] [--mppt DEVICE]:
// a simulated Millswood 250W PMU on a SocketCAN interface (interface.md section 3.3), a bench
// stand-in for the real unit, optionally with the solar-boat battery (MG BMS) and MPPTs
// beside it. Repeat --address, --battery, --mppt for several devices. Stops on SIGTERM/SIGINT.
// The world options (--engine, --internal-temperature, --state-of-charge, ...) are the keys
// of pmu-service's `sim:` mappings (interface.md section 4.4) under the same names, so a
// bench set up one way can be set up the other.
//
// sim_options.hpp reads and checks the command line; this file plays the devices it names.

#include <chrono>
#include <cstdint>
#include <cstdio>
#include <variant>

#include "pmu/sim/bus_runner.hpp"
#include "pmu/transport/socketcan_bus.hpp"
#include "pmu/transport/stop_signals.hpp"
#include "sim_options.hpp"

namespace {

using pmu::tools::SimOptions;

void add_pmus(pmu::sim::BusRunner& runner, const SimOptions& o, pmu::transport::SystemClock& clock) {
  for (std::size_t i = 0; i < o.addresses.size(); ++i) {
    pmu::sim::DeviceConfig d;
    d.address = static_cast<std::uint16_t>(o.addresses[i]);
    d.serial_number = static_cast<std::uint16_t>(o.serial + static_cast<int>(i));
    d.firmware = o.firmware;
    runner.add(d);
    runner.with_model(d.address, [&](pmu::sim::PmuModel& m) {
      m.set_plant(o.pmu_plant, clock.steady_now());
      if (o.engine_running) m.set_engine_running(true, clock.steady_now());
      pmu::sim::Faults faults = m.faults();
      faults.silent = o.silent;
      faults.ignored_set = o.ignored_set;
      m.set_faults(faults);
    });
  }
}

void add_solar_devices(pmu::sim::BusRunner& runner, const SimOptions& o, pmu::transport::SystemClock& clock) {
  for (const int node : o.batteries) {
    pmu::sim::BatterySimConfig b;
    b.node = static_cast<std::uint8_t>(node);
    b.cells = o.cells;
    b.period = std::chrono::milliseconds(o.battery_period_ms);
    if (o.state_of_charge) b.initial_soc = *o.state_of_charge / 100.0;
    b.cell_voltages = o.cell_voltages;
    runner.add_battery(b);
    runner.with_battery(b.node, [&](pmu::sim::BatteryModel& m) { m.set_faults({o.battery_silent, o.battery_garble}); });
  }
  for (const int device : o.mppts) {
    pmu::sim::MpptSimConfig m;
    m.device = static_cast<std::uint8_t>(device);
    m.period = std::chrono::milliseconds(o.mppt_period_ms);
    if (o.panels) m.panels = *o.panels;
    runner.add_mppt(m);
    runner.with_mppt(m.device, [&](pmu::sim::MpptModel& model) { model.set_faults({o.mppt_silent, o.mppt_garble}); });
  }
  // The batteries and MPPTs share one plant: set its sun and load through any of them.
  const auto world = [&](pmu::sim::SolarPlant& plant) {
    plant.set_load(o.load, clock.steady_now());
    if (o.sun) plant.set_irradiance(*o.sun, clock.steady_now());
  };
  if (!o.batteries.empty())
    runner.with_battery(static_cast<std::uint8_t>(o.batteries.front()),
                        [&](pmu::sim::BatteryModel& b) { world(b.plant()); });
  else if (!o.mppts.empty())
    runner.with_mppt(static_cast<std::uint8_t>(o.mppts.front()), [&](pmu::sim::MpptModel& m) { world(m.plant()); });
}

// Plays the devices on o.iface until SIGTERM or SIGINT: exit 0, or 1 when the bus fails.
int run_bench(const SimOptions& o) {
  pmu::transport::StopSignals stop;  // before the runner's thread, which inherits the mask
  try {
    pmu::transport::SystemClock clock;
    pmu::transport::SocketCanOptions options;
    options.filters = pmu::transport::default_filters(false);
    pmu::sim::BusRunner runner(pmu::transport::SocketCanBus::open(o.iface, options, clock), clock);
    add_pmus(runner, o, clock);
    add_solar_devices(runner, o, clock);
    std::fprintf(stderr, "pmu-sim: %zu PMU(s), %zu battery(ies), %zu MPPT(s) on %s, firmware %s\n", o.addresses.size(),
                 o.batteries.size(), o.mppts.size(), o.iface.c_str(), o.firmware_text.c_str());
    runner.start();
    stop.wait();
    runner.stop();
  } catch (const std::exception& e) {
    std::fprintf(stderr, "pmu-sim: %s\n", e.what());
    return 1;
  }
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  const auto options = pmu::tools::parse_sim_options(argc, argv);
  if (const auto* status = std::get_if<int>(&options)) return *status;
  return run_bench(std::get<SimOptions>(options));
}
