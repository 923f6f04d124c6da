#pragma once
// One PMU's derived energy (interface.md 1.8): its voltages and currents in, with their
// receive times, Figures out at most once per kReportPeriod of receive time.
//
//   power of a rail    V x I of the latest samples of both, NaN once either is older than
//                      `max_gap` at the time of the figures; the signs of table 3 kept
//   battery power      V x I, positive into the battery: table 4 counts "current into
//                      battery", and table 3's signed battery current follows it
//   generator power    the balance: the four outputs' power plus both batteries' (into them).
//                      The PMU measures no generator current; its conversion losses are
//                      not in the balance, so the generator gives somewhat more than this.
//                      With the generator off the batteries feed the outputs and the
//                      balance is 0 to within the fields' resolution.
//   energy used        -(battery power) integrated over each currents sample (EnergyIntegral),
//                      Wh since this object was made: discharge less charge
//   endurance          VoltageTrendEndurance against the battery's critical voltage
//
// Pure: no clock, no I/O. Not thread-safe: the owner serialises calls.

#include <chrono>
#include <optional>

#include "pmu/codec/messages.hpp"
#include "pmu/energy/endurance.hpp"
#include "pmu/energy/energy_integral.hpp"
#include "pmu/energy/figures.hpp"

namespace pmu::energy {

// The battery_a_critical_voltage and battery_b_critical_voltage alarms' limits as the
// device's config sets them (V).
struct CriticalVoltages {
  double battery_a = kUnknown;
  double battery_b = kUnknown;
};

class PmuEnergy {
 public:
  // `max_gap` > 0: the longest interval between samples that is still integrated, and the
  // age past which a value is no longer used.
  PmuEnergy(CriticalVoltages critical, std::chrono::nanoseconds max_gap) noexcept;

  void on_voltages(Time received, const codec::Voltages& v) noexcept;
  void on_currents(Time received, const codec::Currents& c);

  // The figures as of `now` (a receive time), whether or not a report is due.
  Figures figures(Time now) const noexcept;
  // The figures when a report is due at `now`: the first time both voltages and currents
  // are known, then once kReportPeriod has passed since the last report.
  std::optional<Figures> report(Time now) noexcept;

 private:
  template <class T>
  struct Latest {
    std::optional<Time> at;
    T value{};
  };
  bool fresh(const std::optional<Time>& at, Time now) const noexcept;

  CriticalVoltages critical_;
  std::chrono::nanoseconds max_gap_;
  Latest<codec::Voltages> volts_;
  Latest<codec::Currents> amps_;
  EnergyIntegral out_of_a_, out_of_b_;
  VoltageTrendEndurance trend_a_, trend_b_;
  std::optional<Time> last_report_;
};

}  // namespace pmu::energy
