// pmu-sim IFACE [--address N] [--firmware X.Y] [--serial N]: a simulated Millswood 250W PMU
// on a SocketCAN interface (interface.md section 2), a bench stand-in for the real unit.
// Repeat --address to put several units on the bus. Stops on SIGTERM/SIGINT.

#include <signal.h>
#include <sys/signalfd.h>
#include <unistd.h>

#include <CLI/CLI.hpp>
#include <cstdio>
#include <vector>

#include "pmu/codec/firmware.hpp"
#include "pmu/codec/ids.hpp"
#include "pmu/sim/bus_runner.hpp"
#include "pmu/transport/socketcan_bus.hpp"

int main(int argc, char** argv) {
  CLI::App app{"pmu-sim: a simulated Millswood 250W PMU on a SocketCAN interface"};
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
  CLI11_PARSE(app, argc, argv);

  const auto fw = pmu::codec::parse_firmware(firmware);
  if (!fw) {
    std::fprintf(stderr, "pmu-sim: --firmware '%s' is not a version like 1.16\n", firmware.c_str());
    return 2;
  }
  if (addresses.empty()) addresses.push_back(1);

  sigset_t signals;
  sigemptyset(&signals);
  sigaddset(&signals, SIGTERM);
  sigaddset(&signals, SIGINT);
  pthread_sigmask(SIG_BLOCK, &signals, nullptr);

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
    std::fprintf(stderr, "pmu-sim: %zu PMU(s) on %s, firmware %s\n", addresses.size(), iface.c_str(), firmware.c_str());
    runner.start();
    int sig = 0;
    sigwait(&signals, &sig);
    runner.stop();
  } catch (const std::exception& e) {
    std::fprintf(stderr, "pmu-sim: %s\n", e.what());
    return 1;
  }
  return 0;
}
