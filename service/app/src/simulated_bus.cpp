#include "pmu/app/simulated_bus.hpp"

#include <spdlog/fmt/ranges.h>
#include <spdlog/spdlog.h>

#include <cstdint>
#include <map>
#include <vector>

#include "pmu/codec/encode.hpp"

namespace pmu::service {
namespace {

// The config's words for the models' (the config room does not see sim/).
sim::Garble garble_of(SimGarble g) {
  switch (g) {
    case SimGarble::None: return sim::Garble::None;
    case SimGarble::WrongLength: return sim::Garble::WrongLength;
    case SimGarble::UnknownSubindex: return sim::Garble::UnknownSubindex;
  }
  return sim::Garble::None;
}

sim::Plant plant_of(const PmuSimSettings& s) {
  sim::Plant p;
  if (s.engine_never_starts) p.engine_starts_after.reset();
  if (s.engine_starts_after) p.engine_starts_after = *s.engine_starts_after;
  if (s.internal_temperature) p.internal_temperature = *s.internal_temperature;
  if (s.battery_a_voltage) p.battery_a_voltage = *s.battery_a_voltage;
  if (s.battery_b_voltage) p.battery_b_voltage = *s.battery_b_voltage;
  if (s.starter_ready) p.starter_ready = *s.starter_ready;
  if (s.soa_shutdown) p.soa_shutdown = *s.soa_shutdown;
  if (s.payload_shed) p.payload_shed = *s.payload_shed;
  return p;
}

template <class Settings, class Key>
Settings settings_of(const std::map<Key, Settings>& all, Key key) {
  const auto it = all.find(key);
  return it == all.end() ? Settings{} : it->second;
}

}  // namespace

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
    const auto settings = settings_of(bus.sim.pmus, dev.address);
    if (settings.firmware) d.firmware = *settings.firmware;
    if (settings.serial) d.serial_number = *settings.serial;
    s.simulator->add(d);
    s.simulator->with_model(dev.address, [&](sim::PmuModel& m) {
      const auto now = clock.steady_now();
      m.set_plant(plant_of(settings), now);
      // Unless told otherwise, an engine that is already running makes the generator figures
      // come alive.
      if (settings.engine_running) m.set_engine_running(true, now);
      sim::Faults faults = m.faults();
      faults.silent = settings.silent;
      faults.ignored_set = settings.ignores_set;
      m.set_faults(faults);
    });
    addresses.push_back(dev.address);
  }
  spdlog::info("{}: built-in simulated PMU at address(es) {}", bus.name, fmt::join(addresses, ", "));
  // The bus's batteries and MPPTs are simulated too, on one solar plant: sun on the panels
  // charges the battery, the load discharges it (sim/README.md).
  for (const auto& battery : bus.batteries) {
    sim::BatterySimConfig c;
    c.node = battery.node;
    c.period = battery.period;
    // The simulated pack is the battery the config describes, so its BMS's time to go and
    // pmu/bms_energy's endurance count the same ampere-hours.
    if (battery.capacity_ah) c.capacity_ah = *battery.capacity_ah;
    const auto settings = settings_of(bus.sim.batteries, battery.node);
    if (settings.state_of_charge) c.initial_soc = *settings.state_of_charge / 100.0;
    if (!settings.cell_voltages.empty()) c.cells = static_cast<int>(settings.cell_voltages.size());
    if (settings.cells) c.cells = *settings.cells;
    c.cell_voltages = settings.cell_voltages;
    s.simulator->add_battery(c);
    s.simulator->with_battery(c.node, [&](sim::BatteryModel& m) {
      m.set_faults({settings.silent, garble_of(settings.garble)});
    });
    spdlog::info("{}: built-in simulated battery (BMS) at node {}", bus.name, battery.node);
  }
  for (const auto& mppt : bus.mppts) {
    sim::MpptSimConfig c;
    c.device = mppt.device;
    c.period = mppt.period;
    const auto settings = settings_of(bus.sim.mppts, mppt.device);
    if (settings.panels) c.panels = *settings.panels;
    s.simulator->add_mppt(c);
    s.simulator->with_mppt(c.device, [&](sim::MpptModel& m) {
      m.set_faults({settings.silent, garble_of(settings.garble)});
    });
    spdlog::info("{}: built-in simulated MPPT, device {}", bus.name, mppt.device);
  }
  s.service_end = s.network->attach(bus.name);
  return s;
}

}  // namespace pmu::service
