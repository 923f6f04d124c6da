// pmu-sim IFACE [--address N] [--firmware X.Y] [--serial N] [--battery NODE] [--mppt DEVICE]:
// a simulated Millswood 250W PMU on a SocketCAN interface (interface.md section 3.3), a bench
// stand-in for the real unit, optionally with the solar-boat battery (MG BMS) and MPPTs
// beside it. Repeat --address, --battery, --mppt for several devices. Stops on SIGTERM/SIGINT.
// The world options (--engine, --internal-temperature, --state-of-charge, ...) are the keys
// of pmu-service's `sim:` mappings (interface.md section 4.4) under the same names, so a
// bench set up one way can be set up the other.

#include <signal.h>
#include <unistd.h>

#include <CLI/CLI.hpp>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <optional>
#include <sstream>
#include <string>
#include <string_view>
#include <vector>

#include "pmu/codec/firmware.hpp"
#include "pmu/codec/parameters.hpp"
#include "pmu/codec/ids.hpp"
#include "pmu/codec/telemetry.hpp"
#include "pmu/sim/bus_runner.hpp"
#include "pmu/transport/socketcan_bus.hpp"
#include "pmu/transport/stop_signals.hpp"
#include "pmu/version.hpp"

namespace {

// MIN..MAX for a number option, said as the config says it ("not in range -127 to 127"):
// CLI::Range prints a double bound with six decimals.
CLI::Validator range(double min, double max) {
  std::ostringstream name;
  name << "[" << min << " - " << max << "]";
  return CLI::Validator(
      [min, max](std::string& text) -> std::string {
        double v = 0;
        if (!CLI::detail::lexical_cast(text, v) || !std::isfinite(v)) return "Value " + text + " is not a number";
        if (v >= min && v <= max) return {};
        std::ostringstream m;
        m << "Value " << text << " not in range " << min << " to " << max;
        return m.str();
      },
      name.str());
}

// What a field of the PMU's telemetry carries (codec/telemetry.hpp), as pmu-service's config
// checks it: a plant value beyond it would go out clamped.
template <class Packet>
CLI::Validator field_range(std::string_view field) {
  for (const auto& f : pmu::codec::Telemetry<Packet>::fields)
    if (f.name == field) return range(f.min(), f.max());
  return range(0, 0);
}

// "never" (a flooded engine), or seconds 0..3600.
std::optional<std::optional<pmu::sim::Duration>> engine_starts_after_of(const std::string& text) {
  if (text == "never") return std::optional<pmu::sim::Duration>{};
  char* end = nullptr;
  const double s = std::strtod(text.c_str(), &end);
  if (text.empty() || end != text.c_str() + text.size() || !std::isfinite(s) || s < 0 || s > 3600) return std::nullopt;
  return std::optional<pmu::sim::Duration>{std::chrono::duration_cast<pmu::sim::Duration>(std::chrono::duration<double>(s))};
}

pmu::sim::Garble garble_of(const std::string& name) {
  if (name == "wrong_length") return pmu::sim::Garble::WrongLength;
  if (name == "unknown_subindex") return pmu::sim::Garble::UnknownSubindex;
  return pmu::sim::Garble::None;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"pmu-sim: a simulated Millswood 250W PMU (and solar-boat battery/MPPTs) on a SocketCAN interface"};
  app.set_version_flag("--version", "pmu-sim " PMU_VERSION_TEXT);
  std::string iface, firmware = "1.17";
  std::vector<int> addresses;
  int serial = 1;
  bool engine_running = true;
  app.add_option("iface", iface, "SocketCAN interface, e.g. vcan0")->required();
  app.add_option("--address", addresses, "CAN address (repeat for several units; default 1)")
      ->check(CLI::Range(0, int{pmu::codec::kMaxDeviceAddress}));
  app.add_option("--firmware", firmware, "Firmware version to behave as, 1.12..1.17 (default 1.17)");
  app.add_option("--serial", serial, "Serial number of the first unit (the next get +1)")->check(CLI::Range(0, 65535));
  std::string engine = "running";
  auto* engine_opt = app.add_option("--engine", engine, "The engine at power-up: running (default) or stopped")
                         ->check(CLI::IsMember({"running", "stopped"}));
  bool engine_stopped = false;
  app.add_flag("--engine-stopped", engine_stopped, "The same as --engine stopped")->excludes(engine_opt);
  std::string engine_starts_after;
  app.add_option("--engine-starts-after", engine_starts_after,
                 "Seconds of cranking before the engine fires, 0..3600, or never (a flooded engine: "
                 "only CT or an engine stop ends the cranking; default 2)");
  pmu::sim::Plant pmu_plant;  // the PMUs' world
  app.add_option("--internal-temperature", pmu_plant.internal_temperature,
                 "Internal temperature in degC (default 35); above the stored T_U the PMU is in thermal shutdown")
      ->check(field_range<pmu::codec::Temperatures>("internal"));
  app.add_option("--battery-a-voltage", pmu_plant.battery_a_voltage, "Battery A terminal voltage in V (default 22.2)")
      ->check(field_range<pmu::codec::Voltages>("battery_a"));
  app.add_option("--battery-b-voltage", pmu_plant.battery_b_voltage, "Battery B terminal voltage in V (default 22.2)")
      ->check(field_range<pmu::codec::Voltages>("battery_b"));
  std::string starter_ready = "true";
  app.add_option("--starter-ready", starter_ready, "Starter-ready flag: true (default) or false")
      ->check(CLI::IsMember({"true", "false"}));
  app.add_flag("--soa-shutdown", pmu_plant.soa_shutdown, "Report the SOA shutdown flag (firmware 1.16+)");
  app.add_flag("--payload-shed", pmu_plant.payload_shed, "Report payload shedding");
  bool silent = false;
  app.add_flag("--silent", silent, "The PMUs are off the bus: they hear and send nothing");
  std::string ignores_set;
  app.add_option("--ignores-set", ignores_set,
                 "A stored parameter the PMUs' memory does not take: its sets change nothing, so a read-back "
                 "shows the old value");
  bool no_pmu = false;
  std::vector<int> batteries, mppts;
  int cells = 12, battery_period_ms = 1000, mppt_period_ms = 1000;
  double load = pmu::sim::SolarWorld{}.load_current;
  std::optional<double> sun;
  app.add_flag("--no-pmu", no_pmu, "No PMU: only the batteries and MPPTs given")->excludes("--address");
  app.add_option("--battery", batteries, "Also play an MG battery's BMS with this CANopen node id (repeat; 2 gives the "
                                         "document's ids 0x202/0x302/0x402/0x482)")
      ->check(CLI::Range(1, 127));
  app.add_option("--mppt", mppts, "Also play an MPPT with this device id (repeat; COB-ID 0x4E6 + 8 * id)")
      ->check(CLI::Range(0, 7));
  auto* cells_opt =
      app.add_option("--cells", cells, "Cells in series of each battery (default 12)")->check(CLI::Range(1, 15));
  app.add_option("--battery-period", battery_period_ms, "Milliseconds in which a battery sends all its values "
                                                        "(default 1000)")
      ->check(CLI::Range(1, 3600000));
  app.add_option("--mppt-period", mppt_period_ms, "Milliseconds in which an MPPT sends all its values (default 1000)")
      ->check(CLI::Range(1, 3600000));
  app.add_option("--load", load, "Amps drawn from the batteries (default 5)")->check(CLI::Range(0.0, 300.0));
  app.add_option("--sun", sun, "Fixed irradiance in W/m2 (default: a slow cycle, 300..900 over 10 minutes)")
      ->check(CLI::Range(0.0, 1500.0));
  // A world option for a device that is not played would do nothing without saying so.
  for (const char* pmu_option : {"--engine", "--engine-starts-after", "--internal-temperature", "--battery-a-voltage",
                                  "--battery-b-voltage", "--starter-ready", "--soa-shutdown", "--payload-shed",
                                  "--silent", "--ignores-set"})
    app.get_option("--no-pmu")->excludes(pmu_option);
  auto* battery_opt = app.get_option("--battery");
  auto* mppt_opt = app.get_option("--mppt");
  std::optional<double> state_of_charge;
  app.add_option("--state-of-charge", state_of_charge, "Each battery's state of charge at power-up in % (default 80)")
      ->check(range(0, 100))
      ->needs(battery_opt);
  std::vector<double> cell_voltages;
  app.add_option("--cell-voltages", cell_voltages,
                     "Fixed cell voltages in V, 0..5, cell 1 first, comma-separated, one per cell (they set --cells); "
                     "default: the cells follow the charge")
          ->delimiter(',')
          ->check(range(0, 5))
          ->needs(battery_opt);
  std::string battery_garble = "none", mppt_garble = "none";
  app.add_option("--battery-garble", battery_garble,
                 "Spoil every battery frame: none (default), wrong_length or unknown_subindex")
      ->check(CLI::IsMember({"none", "wrong_length", "unknown_subindex"}))
      ->needs(battery_opt);
  bool battery_silent = false, mppt_silent = false;
  app.add_flag("--battery-silent", battery_silent, "The batteries send nothing")->needs(battery_opt);
  std::optional<int> panels;
  app.add_option("--panels", panels, "Panels on channels 1..N of each MPPT, 0..4 (default 4)")
      ->check(CLI::Range(0, 4))
      ->needs(mppt_opt);
  app.add_option("--mppt-garble", mppt_garble, "Spoil every MPPT frame: none (default), wrong_length or unknown_subindex")
      ->check(CLI::IsMember({"none", "wrong_length", "unknown_subindex"}))
      ->needs(mppt_opt);
  app.add_flag("--mppt-silent", mppt_silent, "The MPPTs send nothing")->needs(mppt_opt);
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    // app.exit prints the help or the reason; bad usage is exit status 2 (the man page),
    // not CLI11's own codes (105 for a value out of range).
    return app.exit(e) == 0 ? 0 : 2;
  }

  std::optional<pmu::codec::Parameter> ignored_set;
  if (!ignores_set.empty()) {
    ignored_set = pmu::codec::parameter_from_name(ignores_set);
    if (!ignored_set) {
      std::fprintf(stderr, "pmu-sim: --ignores-set '%s' is not a stored parameter\n", ignores_set.c_str());
      return 2;
    }
  }
  const auto fw = pmu::codec::parse_firmware(firmware);
  if (!fw) {
    std::fprintf(stderr, "pmu-sim: --firmware '%s' is not a version like 1.16\n", firmware.c_str());
    return 2;
  }
  // Every argument is checked before the bus is opened (interface.md 3.3): the model would
  // refuse this firmware only once the bus is open.
  if (!pmu::codec::is_described(*fw)) {
    std::fprintf(stderr, "pmu-sim: --firmware %s: the simulator is firmware %s..%s (the versions the protocol "
                         "documents describe)\n",
                 firmware.c_str(), pmu::codec::to_string(pmu::codec::kOldestDescribedFirmware).c_str(),
                 pmu::codec::to_string(pmu::codec::kCurrentFirmware).c_str());
    return 2;
  }
  if (engine_stopped || engine == "stopped") engine_running = false;
  pmu_plant.starter_ready = starter_ready == "true";
  if (!engine_starts_after.empty()) {
    const auto after = engine_starts_after_of(engine_starts_after);
    if (!after) {
      std::fprintf(stderr, "pmu-sim: --engine-starts-after '%s' is not seconds (0..3600) or never\n",
                   engine_starts_after.c_str());
      return 2;
    }
    pmu_plant.engine_starts_after = *after;
  }
  if (!cell_voltages.empty()) {
    if (cell_voltages.size() > 15) {
      std::fprintf(stderr, "pmu-sim: --cell-voltages gives %zu voltages; a battery has 1..15 cells\n",
                   cell_voltages.size());
      return 2;
    }
    if (cells_opt->count() > 0 && static_cast<std::size_t>(cells) != cell_voltages.size()) {
      std::fprintf(stderr, "pmu-sim: --cell-voltages gives %zu voltages but --cells is %d (one per cell)\n",
                   cell_voltages.size(), cells);
      return 2;
    }
    cells = static_cast<int>(cell_voltages.size());
  }
  if (addresses.empty() && !no_pmu) addresses.push_back(1);
  if (addresses.empty() && batteries.empty() && mppts.empty()) {
    std::fprintf(stderr, "pmu-sim: --no-pmu needs --battery or --mppt\n");
    return 2;
  }

  pmu::transport::StopSignals stop;  // before the runner's thread, which inherits the mask

  try {
    pmu::transport::SystemClock clock;
    pmu::transport::SocketCanOptions options;
    options.filters = pmu::transport::default_filters(false);
    pmu::sim::BusRunner runner(pmu::transport::SocketCanBus::open(iface, options, clock), clock);
    for (std::size_t i = 0; i < addresses.size(); ++i) {
      pmu::sim::DeviceConfig d;
      d.address = static_cast<std::uint16_t>(addresses[i]);
      d.serial_number = static_cast<std::uint16_t>(serial + static_cast<int>(i));
      d.firmware = *fw;
      runner.add(d);
      runner.with_model(d.address, [&](pmu::sim::PmuModel& m) {
        m.set_plant(pmu_plant, clock.steady_now());
        if (engine_running) m.set_engine_running(true, clock.steady_now());
        pmu::sim::Faults faults = m.faults();
        faults.silent = silent;
        faults.ignored_set = ignored_set;
        m.set_faults(faults);
      });
    }
    for (const int node : batteries) {
      pmu::sim::BatterySimConfig b;
      b.node = static_cast<std::uint8_t>(node);
      b.cells = cells;
      b.period = std::chrono::milliseconds(battery_period_ms);
      if (state_of_charge) b.initial_soc = *state_of_charge / 100.0;
      b.cell_voltages = cell_voltages;
      runner.add_battery(b);
      runner.with_battery(b.node, [&](pmu::sim::BatteryModel& m) { m.set_faults({battery_silent, garble_of(battery_garble)}); });
    }
    for (const int device : mppts) {
      pmu::sim::MpptSimConfig m;
      m.device = static_cast<std::uint8_t>(device);
      m.period = std::chrono::milliseconds(mppt_period_ms);
      if (panels) m.panels = *panels;
      runner.add_mppt(m);
      runner.with_mppt(m.device, [&](pmu::sim::MpptModel& model) { model.set_faults({mppt_silent, garble_of(mppt_garble)}); });
    }
    // The batteries and MPPTs share one plant: set its sun and load through any of them.
    const auto world = [&](pmu::sim::SolarPlant& plant) {
      plant.set_load(load, clock.steady_now());
      if (sun) plant.set_irradiance(*sun, clock.steady_now());
    };
    if (!batteries.empty())
      runner.with_battery(static_cast<std::uint8_t>(batteries.front()), [&](pmu::sim::BatteryModel& b) { world(b.plant()); });
    else if (!mppts.empty())
      runner.with_mppt(static_cast<std::uint8_t>(mppts.front()), [&](pmu::sim::MpptModel& m) { world(m.plant()); });
    std::fprintf(stderr, "pmu-sim: %zu PMU(s), %zu battery(ies), %zu MPPT(s) on %s, firmware %s\n", addresses.size(),
                 batteries.size(), mppts.size(), iface.c_str(), firmware.c_str());
    runner.start();
    stop.wait();
    runner.stop();
  } catch (const std::exception& e) {
    std::fprintf(stderr, "pmu-sim: %s\n", e.what());
    return 1;
  }
  return 0;
}
