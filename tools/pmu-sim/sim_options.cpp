#include "sim_options.hpp"

#include <CLI/CLI.hpp>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <sstream>
#include <string_view>

#include "pmu/codec/ids.hpp"
#include "pmu/codec/telemetry.hpp"
#include "pmu/version.hpp"

namespace pmu::tools {
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
  return std::optional<pmu::sim::Duration>{
      std::chrono::duration_cast<pmu::sim::Duration>(std::chrono::duration<double>(s))};
}

pmu::sim::Garble garble_of(const std::string& name) {
  if (name == "wrong_length") return pmu::sim::Garble::WrongLength;
  if (name == "unknown_subindex") return pmu::sim::Garble::UnknownSubindex;
  return pmu::sim::Garble::None;
}

// The options as given, before the checks CLI11 cannot make.
struct GivenText {
  std::string firmware = "1.17";
  std::string engine = "running";
  bool engine_stopped = false;
  std::string engine_starts_after;
  std::string starter_ready = "true";
  std::string ignores_set;
  bool no_pmu = false;
  const CLI::Option* cells_option = nullptr;
  std::string battery_garble = "none", mppt_garble = "none";
};

void add_pmu_options(CLI::App& app, SimOptions& o, GivenText& given) {
  app.add_option("iface", o.iface, "SocketCAN interface, e.g. vcan0")->required();
  app.add_option("--address", o.addresses, "CAN address (repeat for several units; default 1)")
      ->check(CLI::Range(0, int{pmu::codec::kMaxDeviceAddress}));
  app.add_option("--firmware", given.firmware, "Firmware version to behave as, 1.12..1.17 (default 1.17)");
  app.add_option("--serial", o.serial, "Serial number of the first unit (the next get +1)")->check(CLI::Range(0, 65535));
  auto* engine_opt = app.add_option("--engine", given.engine, "The engine at power-up: running (default) or stopped")
                         ->check(CLI::IsMember({"running", "stopped"}));
  app.add_flag("--engine-stopped", given.engine_stopped, "The same as --engine stopped")->excludes(engine_opt);
  app.add_option("--engine-starts-after", given.engine_starts_after,
                 "Seconds of cranking before the engine fires, 0..3600, or never (a flooded engine: "
                 "only CT or an engine stop ends the cranking; default 2)");
  app.add_option("--internal-temperature", o.pmu_plant.internal_temperature,
                 "Internal temperature in degC (default 35); above the stored T_U the PMU is in thermal shutdown")
      ->check(field_range<pmu::codec::Temperatures>("internal"));
  app.add_option("--battery-a-voltage", o.pmu_plant.battery_a_voltage, "Battery A terminal voltage in V (default 22.2)")
      ->check(field_range<pmu::codec::Voltages>("battery_a"));
  app.add_option("--battery-b-voltage", o.pmu_plant.battery_b_voltage, "Battery B terminal voltage in V (default 22.2)")
      ->check(field_range<pmu::codec::Voltages>("battery_b"));
  app.add_option("--starter-ready", given.starter_ready, "Starter-ready flag: true (default) or false")
      ->check(CLI::IsMember({"true", "false"}));
  app.add_flag("--soa-shutdown", o.pmu_plant.soa_shutdown, "Report the SOA shutdown flag (firmware 1.16+)");
  app.add_flag("--payload-shed", o.pmu_plant.payload_shed, "Report payload shedding");
  app.add_flag("--silent", o.silent, "The PMUs are off the bus: they hear and send nothing");
  app.add_option("--ignores-set", given.ignores_set,
                 "A stored parameter the PMUs' memory does not take: its sets change nothing, so a read-back "
                 "shows the old value");
}

void add_solar_options(CLI::App& app, SimOptions& o, GivenText& given) {
  app.add_flag("--no-pmu", given.no_pmu, "No PMU: only the batteries and MPPTs given")->excludes("--address");
  app.add_option("--battery", o.batteries,
                 "Also play an MG battery's BMS with this CANopen node id (repeat; 2 gives the "
                 "document's ids 0x202/0x302/0x402/0x482)")
      ->check(CLI::Range(1, 127));
  app.add_option("--mppt", o.mppts, "Also play an MPPT with this device id (repeat; COB-ID 0x4E6 + 8 * id)")
      ->check(CLI::Range(0, 7));
  given.cells_option =
      app.add_option("--cells", o.cells, "Cells in series of each battery (default 12)")->check(CLI::Range(1, 15));
  app.add_option("--battery-period", o.battery_period_ms,
                 "Milliseconds in which a battery sends all its values "
                 "(default 1000)")
      ->check(CLI::Range(1, 3600000));
  app.add_option("--mppt-period", o.mppt_period_ms, "Milliseconds in which an MPPT sends all its values (default 1000)")
      ->check(CLI::Range(1, 3600000));
  app.add_option("--load", o.load, "Amps drawn from the batteries (default 5)")->check(CLI::Range(0.0, 300.0));
  app.add_option("--sun", o.sun, "Fixed irradiance in W/m2 (default: a slow cycle, 300..900 over 10 minutes)")
      ->check(CLI::Range(0.0, 1500.0));
  // A world option for a device that is not played would do nothing without saying so.
  for (const char* pmu_option :
       {"--engine", "--engine-starts-after", "--internal-temperature", "--battery-a-voltage", "--battery-b-voltage",
        "--starter-ready", "--soa-shutdown", "--payload-shed", "--silent", "--ignores-set"})
    app.get_option("--no-pmu")->excludes(pmu_option);
  auto* battery_opt = app.get_option("--battery");
  auto* mppt_opt = app.get_option("--mppt");
  app.add_option("--state-of-charge", o.state_of_charge, "Each battery's state of charge at power-up in % (default 80)")
      ->check(range(0, 100))
      ->needs(battery_opt);
  app.add_option("--cell-voltages", o.cell_voltages,
                 "Fixed cell voltages in V, 0..5, cell 1 first, comma-separated, one per cell (they set --cells); "
                 "default: the cells follow the charge")
      ->delimiter(',')
      ->check(range(0, 5))
      ->needs(battery_opt);
  app.add_option("--battery-garble", given.battery_garble,
                 "Spoil every battery frame: none (default), wrong_length or unknown_subindex")
      ->check(CLI::IsMember({"none", "wrong_length", "unknown_subindex"}))
      ->needs(battery_opt);
  app.add_flag("--battery-silent", o.battery_silent, "The batteries send nothing")->needs(battery_opt);
  app.add_option("--panels", o.panels, "Panels on channels 1..N of each MPPT, 0..4 (default 4)")
      ->check(CLI::Range(0, 4))
      ->needs(mppt_opt);
  app.add_option("--mppt-garble", given.mppt_garble,
                 "Spoil every MPPT frame: none (default), wrong_length or unknown_subindex")
      ->check(CLI::IsMember({"none", "wrong_length", "unknown_subindex"}))
      ->needs(mppt_opt);
  app.add_flag("--mppt-silent", o.mppt_silent, "The MPPTs send nothing")->needs(mppt_opt);
}

// What CLI11 cannot check: the names and numbers it takes as text, and the options that
// depend on each other. False after saying what is wrong.
bool take_given(SimOptions& o, const GivenText& given) {
  if (!given.ignores_set.empty()) {
    o.ignored_set = pmu::codec::parameter_from_name(given.ignores_set);
    if (!o.ignored_set) {
      std::fprintf(stderr, "pmu-sim: --ignores-set '%s' is not a stored parameter\n", given.ignores_set.c_str());
      return false;
    }
  }
  const auto fw = pmu::codec::parse_firmware(given.firmware);
  if (!fw) {
    std::fprintf(stderr, "pmu-sim: --firmware '%s' is not a version like 1.16\n", given.firmware.c_str());
    return false;
  }
  // Every argument is checked before the bus is opened (interface.md 3.3): the model would
  // refuse this firmware only once the bus is open.
  if (!pmu::codec::is_described(*fw)) {
    std::fprintf(stderr,
                 "pmu-sim: --firmware %s: the simulator is firmware %s..%s (the versions the protocol "
                 "documents describe)\n",
                 given.firmware.c_str(), pmu::codec::to_string(pmu::codec::kOldestDescribedFirmware).c_str(),
                 pmu::codec::to_string(pmu::codec::kCurrentFirmware).c_str());
    return false;
  }
  o.firmware = *fw;
  o.firmware_text = given.firmware;
  if (given.engine_stopped || given.engine == "stopped") o.engine_running = false;
  o.pmu_plant.starter_ready = given.starter_ready == "true";
  if (!given.engine_starts_after.empty()) {
    const auto after = engine_starts_after_of(given.engine_starts_after);
    if (!after) {
      std::fprintf(stderr, "pmu-sim: --engine-starts-after '%s' is not seconds (0..3600) or never\n",
                   given.engine_starts_after.c_str());
      return false;
    }
    o.pmu_plant.engine_starts_after = *after;
  }
  if (!o.cell_voltages.empty()) {
    if (o.cell_voltages.size() > 15) {
      std::fprintf(stderr, "pmu-sim: --cell-voltages gives %zu voltages; a battery has 1..15 cells\n",
                   o.cell_voltages.size());
      return false;
    }
    if (given.cells_option->count() > 0 && static_cast<std::size_t>(o.cells) != o.cell_voltages.size()) {
      std::fprintf(stderr, "pmu-sim: --cell-voltages gives %zu voltages but --cells is %d (one per cell)\n",
                   o.cell_voltages.size(), o.cells);
      return false;
    }
    o.cells = static_cast<int>(o.cell_voltages.size());
  }
  if (o.addresses.empty() && !given.no_pmu) o.addresses.push_back(1);
  if (o.addresses.empty() && o.batteries.empty() && o.mppts.empty()) {
    std::fprintf(stderr, "pmu-sim: --no-pmu needs --battery or --mppt\n");
    return false;
  }
  o.battery_garble = garble_of(given.battery_garble);
  o.mppt_garble = garble_of(given.mppt_garble);
  return true;
}

}  // namespace

std::variant<SimOptions, int> parse_sim_options(int argc, char** argv) {
  CLI::App app{"pmu-sim: a simulated Millswood 250W PMU (and solar-boat battery/MPPTs) on a SocketCAN interface"};
  app.set_version_flag("--version", "pmu-sim " PMU_VERSION_TEXT);
  SimOptions o;
  GivenText given;
  add_pmu_options(app, o, given);
  add_solar_options(app, o, given);
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    // app.exit prints the help or the reason; bad usage is exit status 2 (the man page),
    // not CLI11's own codes (105 for a value out of range).
    return app.exit(e) == 0 ? 0 : 2;
  }
  if (!take_given(o, given)) return 2;
  return o;
}

}  // namespace pmu::tools
