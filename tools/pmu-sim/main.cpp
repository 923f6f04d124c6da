// pmu-sim IFACE [--address N] [--firmware X.Y] [--serial N] [--battery NODE] [--mppt DEVICE]:
// a simulated Millswood 250W PMU on a SocketCAN interface (interface.md section 3.3), a bench
// stand-in for the real unit, optionally with the solar-boat battery (MG BMS) and MPPTs
// beside it. Repeat --address, --battery, --mppt for several devices. Stops on SIGTERM/SIGINT.

#include <signal.h>
#include <unistd.h>

#include <CLI/CLI.hpp>
#include <chrono>
#include <cstdio>
#include <optional>
#include <vector>

#include "pmu/codec/firmware.hpp"
#include "pmu/codec/ids.hpp"
#include "pmu/sim/bus_runner.hpp"
#include "pmu/transport/socketcan_bus.hpp"
#include "pmu/transport/stop_signals.hpp"
#include "pmu/version.hpp"

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
  app.add_option("--firmware", firmware, "Firmware version to behave as: 1.12, 1.14, 1.16 or 1.17");
  app.add_option("--serial", serial, "Serial number of the first unit (the next get +1)")->check(CLI::Range(0, 65535));
  app.add_flag("!--engine-stopped", engine_running, "Start with the engine stopped (default: running)");
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
  app.add_option("--cells", cells, "Cells in series of each battery (default 12)")->check(CLI::Range(1, 15));
  app.add_option("--battery-period", battery_period_ms, "Milliseconds in which a battery sends all its values "
                                                        "(default 1000)")
      ->check(CLI::Range(1, 3600000));
  app.add_option("--mppt-period", mppt_period_ms, "Milliseconds in which an MPPT sends all its values (default 1000)")
      ->check(CLI::Range(1, 3600000));
  app.add_option("--load", load, "Amps drawn from the batteries (default 5)")->check(CLI::Range(0.0, 300.0));
  app.add_option("--sun", sun, "Fixed irradiance in W/m2 (default: a slow cycle, 300..900 over 10 minutes)")
      ->check(CLI::Range(0.0, 1500.0));
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    // app.exit prints the help or the reason; bad usage is exit status 2 (the man page),
    // not CLI11's own codes (105 for a value out of range).
    return app.exit(e) == 0 ? 0 : 2;
  }

  const auto fw = pmu::codec::parse_firmware(firmware);
  if (!fw) {
    std::fprintf(stderr, "pmu-sim: --firmware '%s' is not a version like 1.16\n", firmware.c_str());
    return 2;
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
      if (engine_running)
        runner.with_model(d.address, [&](pmu::sim::PmuModel& m) { m.set_engine_running(true, clock.steady_now()); });
    }
    for (const int node : batteries) {
      pmu::sim::BatterySimConfig b;
      b.node = static_cast<std::uint8_t>(node);
      b.cells = cells;
      b.period = std::chrono::milliseconds(battery_period_ms);
      runner.add_battery(b);
    }
    for (const int device : mppts) {
      pmu::sim::MpptSimConfig m;
      m.device = static_cast<std::uint8_t>(device);
      m.period = std::chrono::milliseconds(mppt_period_ms);
      runner.add_mppt(m);
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
