#include "pmu/app/simulated_bus.hpp"

#include <spdlog/fmt/ranges.h>
#include <spdlog/spdlog.h>

#include <cstdint>
#include <vector>

#include "pmu/codec/encode.hpp"

namespace pmu::service {

SimulatedBus make_simulated_bus(const BusConfig& bus, const transport::Clock& clock) {
  SimulatedBus s;
  s.network = std::make_unique<transport::SimulatedNetwork>(clock);
  s.simulator = std::make_unique<sim::BusRunner>(s.network->attach("pmu-sim"), clock);
  std::vector<DeviceConfig> devices = bus.devices;
  if (devices.empty()) devices.push_back(bus.discovered_defaults);
  std::vector<std::uint16_t> addresses;
  for (const auto& dev : devices) {
    sim::DeviceConfig d;
    d.address = dev.address;
    d.serial_number = static_cast<std::uint16_t>(1000 + dev.address);
    // Stream what the service expects, so the demo shows every topic at the configured rate.
    const auto pp = codec::to_raw(codec::Parameter::PacketPeriod,
                                  codec::duration_value(codec::Parameter::PacketPeriod, dev.period));
    if (pp) d.parameters.set_raw(codec::Parameter::PacketPeriod, *pp);  // the config checked it is a PP
    d.parameters.set_raw(codec::Parameter::PacketsStreamed, dev.groups);
    s.simulator->add(d);
    // An engine that is already running makes the generator figures come alive.
    s.simulator->with_model(dev.address, [&](sim::PmuModel& m) { m.set_engine_running(true, clock.steady_now()); });
    addresses.push_back(dev.address);
  }
  spdlog::info("{}: built-in simulated PMU at address(es) {}", bus.name, fmt::join(addresses, ", "));
  // The bus's batteries and MPPTs are simulated too, on one solar plant: sun on the panels
  // charges the battery, the load discharges it (sim/README.md).
  for (const auto& battery : bus.batteries) {
    sim::BatterySimConfig c;
    c.node = battery.node;
    c.period = battery.period;
    s.simulator->add_battery(c);
    spdlog::info("{}: built-in simulated battery (BMS) at node {}", bus.name, battery.node);
  }
  for (const auto& mppt : bus.mppts) {
    sim::MpptSimConfig c;
    c.device = mppt.device;
    c.period = mppt.period;
    s.simulator->add_mppt(c);
    spdlog::info("{}: built-in simulated MPPT, device {}", bus.name, mppt.device);
  }
  s.service_end = s.network->attach(bus.name);
  return s;
}

}  // namespace pmu::service
