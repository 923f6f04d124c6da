#pragma once
// What the service derives from one PMU's voltages and currents (interface.md 1.8), in SI
// units. NaN: not known (a value not yet received or older than kMaxGap, or an estimate that
// cannot be made). Plain data: the DDS side turns it into pmu::v4::Energy.

#include <chrono>
#include <limits>

namespace pmu::energy {

using Time = std::chrono::system_clock::time_point;  // a sample's receive time

inline constexpr double kUnknown = std::numeric_limits<double>::quiet_NaN();

struct BatteryFigures {
  double power = kUnknown;             // W, V x I: positive into the battery (charging)
  double used_wh = 0;                  // Wh out of the battery (discharge less charge) since the start
  double integrated_s = 0;             // s of samples the integral covers (gaps left out)
  double endurance_s = kUnknown;       // s until the voltage reaches critical_voltage
  double critical_voltage = kUnknown;  // V, the battery's critical-voltage alarm limit
};

struct Figures {
  double avionics_power = kUnknown;  // W
  double output_28v_power = kUnknown;
  double payload_power = kUnknown;
  double servo_power = kUnknown;
  double generator_power = kUnknown;  // W, the power balance: outputs plus what goes into the batteries
  BatteryFigures battery_a;
  BatteryFigures battery_b;
};

}  // namespace pmu::energy
