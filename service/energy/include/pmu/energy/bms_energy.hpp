#pragma once
// One BMS-reported battery's derived energy (interface.md 1.8, pmu/bms_energy): its
// pmu/battery values in, with their receive times, BmsFigures out at most once per
// kReportPeriod of receive time.
//
//   power       V x I of the latest values. The battery document gives the current no sign;
//               it is taken as sent, which the service reads as positive into the battery
//               (charging), the simulator's reading (sim/README.md) and the PMU batteries' sign
//   energy used -(power) integrated over each sample (EnergyIntegral), Wh since this object
//               was made: discharge less charge
//   endurance   (state of charge - critical state of charge) / 100 x capacity / filtered
//               discharge current, the current filtered by MeanCurrent; 0 at or below the
//               critical state of charge. NaN while the filtered current is not a discharge
//               (above -kBmsMinDischarge: charging, idle, unknown), without a capacity, or
//               with the state of charge not known
//
// Unlike the PMU's batteries no voltage trend is needed: the BMS counts the charge itself, so
// what is left is its state of charge times the nameplate capacity, and how fast it goes is
// the measured current.
//
// Pure: no clock, no I/O. Not thread-safe: the owner serialises calls.

#include <chrono>
#include <optional>

#include "pmu/energy/energy_integral.hpp"
#include "pmu/energy/figures.hpp"
#include "pmu/energy/mean_current.hpp"

namespace pmu::energy {

// A: a filtered current closer to zero is idle. A BMS's own draw and its sensor's offset are
// tens of mA; at 0.1 A a 20 Ah pack lasts 200 h, longer than any mission, so nothing useful
// is lost by calling it idle.
inline constexpr double kBmsMinDischarge = 0.1;

// The values of one pmu/battery sample the figures use; NaN: not received.
struct BmsReading {
  double voltage = kUnknown;          // V
  double current = kUnknown;          // A, as the BMS sends it: positive into the battery
  double state_of_charge = kUnknown;  // %
};

// What the config says of the battery.
struct BmsSettings {
  double capacity_ah = kUnknown;               // Ah, nameplate; NaN: not configured
  double critical_state_of_charge = kUnknown;  // %, the bms_critical_soc alarm's limit
};

class BmsEnergy {
 public:
  // `max_gap` > 0: the longest interval between samples that is still integrated and keeps
  // the current's window, and the age past which the latest values are no longer used.
  BmsEnergy(BmsSettings settings, std::chrono::nanoseconds max_gap) noexcept;

  void on_sample(Time received, const BmsReading& reading);

  // The figures as of `now` (a receive time), whether or not a report is due.
  BmsFigures figures(Time now) const noexcept;
  // The figures when a report is due at `now`: at the first sample that carries both voltage
  // and current, then once kReportPeriod has passed since the last report.
  std::optional<BmsFigures> report(Time now) noexcept;

 private:
  BmsSettings settings_;
  std::chrono::nanoseconds max_gap_;
  std::optional<Time> latest_at_;
  BmsReading latest_;
  bool known_ = false;  // a sample carried both voltage and current
  EnergyIntegral out_;
  MeanCurrent draw_;
  std::optional<Time> last_report_;
};

}  // namespace pmu::energy
