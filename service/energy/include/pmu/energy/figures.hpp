#pragma once
// What the service derives from one PMU's voltages and currents (interface.md 1.8), and from
// one BMS's pmu/battery values, in SI units. NaN: not known (a value not yet received or
// older than the device's STALE time, or an estimate that cannot be made). Plain data: the
// DDS side turns them into pmu::v5::Energy and pmu::v5::BmsEnergy.

#include <chrono>
#include <limits>

namespace pmu::energy {

using Time = std::chrono::system_clock::time_point;  // a sample's receive time

inline constexpr double kUnknown = std::numeric_limits<double>::quiet_NaN();

// Figures are reported at most this often per device, of the samples' receive time.
inline constexpr std::chrono::seconds kReportPeriod{1};

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

// One battery reported by its BMS (pmu/battery). Signs as the BMS's current: positive into
// the battery (charging).
struct BmsFigures {
  double power = kUnknown;                     // W, V x I of the latest pmu/battery values
  double used_wh = 0;                          // Wh out of the battery (discharge less charge) since the start
  double integrated_s = 0;                     // s of samples the integral covers (gaps left out)
  double endurance_s = kUnknown;               // s until the state of charge reaches the critical one
  double capacity_ah = kUnknown;               // Ah, as configured
  double critical_state_of_charge = kUnknown;  // %, the bms_critical_soc alarm's limit
};

}  // namespace pmu::energy
