#pragma once
// pmu-sim's command line (interface.md section 3.3, pmu-sim(1)), typed and checked whole
// before any bus is opened: the devices to play and the world they report.

#include <optional>
#include <string>
#include <variant>
#include <vector>

#include "pmu/codec/firmware.hpp"
#include "pmu/codec/parameters.hpp"
#include "pmu/sim/config.hpp"
#include "pmu/sim/solar_config.hpp"

namespace pmu::tools {

struct SimOptions {
  std::string iface;
  std::string firmware_text;  // as given, for the start-up line
  pmu::codec::FirmwareVersion firmware;
  // The PMUs: their addresses (empty with --no-pmu), the first one's serial, their world.
  std::vector<int> addresses;
  int serial = 1;
  bool engine_running = true;
  pmu::sim::Plant pmu_plant;
  bool silent = false;
  std::optional<pmu::codec::Parameter> ignored_set;
  // The batteries (CANopen node ids) and MPPTs (device ids), and their shared plant.
  std::vector<int> batteries, mppts;
  int cells = 12, battery_period_ms = 1000, mppt_period_ms = 1000;
  double load = pmu::sim::SolarWorld{}.load_current;
  std::optional<double> sun;
  std::optional<double> state_of_charge;  // %
  std::vector<double> cell_voltages;
  pmu::sim::Garble battery_garble = pmu::sim::Garble::None, mppt_garble = pmu::sim::Garble::None;
  bool battery_silent = false, mppt_silent = false;
  std::optional<int> panels;
};

// The options, or the exit status when the call ends here: 0 after --help or --version,
// 2 after saying what is wrong with an option.
std::variant<SimOptions, int> parse_sim_options(int argc, char** argv);

}  // namespace pmu::tools
