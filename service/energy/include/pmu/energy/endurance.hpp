#pragma once
// The endurance of a battery the PMU measures only by voltage and current (battery A or B): no
// capacity and no state of charge is known, so the estimate extrapolates the voltage's
// trend. Over a sliding window (kWindow) of (receive time, voltage, current) samples:
//
//   filtered draw  the mean current over the window; discharging below -kMinDischarge
//   slope          the least-squares line through the window's voltages, V/s
//   endurance      (fitted voltage now - critical voltage) / -slope, 0 at or below critical
//
// NaN (not known) while the window spans less than kMinSpan, while the mean current is not a
// discharge (charging, idle, unknown), while the fitted line falls less than kMinFall over the
// window (a flat stretch of the discharge curve, or a fall the 0.1 V resolution hides), or
// without a critical voltage.
// A load step (current away from the window's mean by more than kLoadStep or a quarter of it),
// a gap longer than `max_gap` and a clock stepped back restart the window: the step's IR drop would read as a
// slope, and across a gap the trend is not known.
//
// Limits (interface.md 1.8): a lithium cell's voltage is flat through most of its discharge
// and falls steeply at the end, so the figure is long (often NaN) in the middle and shrinks
// fast near the end; it is a trend, not a fuel gauge.

#include <chrono>
#include <deque>

#include "pmu/energy/figures.hpp"

namespace pmu::energy {

inline constexpr std::chrono::seconds kWindow{300};
inline constexpr std::chrono::seconds kMinSpan{60};
inline constexpr double kMinDischarge = 0.1;  // A: one count of the current field (table 3)
inline constexpr double kLoadStep = 0.5;      // A
inline constexpr double kMinFall = 0.05;      // V: half a count of the voltage field (table 2)

class VoltageTrendEndurance {
 public:
  explicit VoltageTrendEndurance(std::chrono::nanoseconds max_gap) noexcept : max_gap_(max_gap) {}

  // NaN in either value ends the window as a gap does.
  void add(Time t, double volts, double amps);
  // Seconds until the fitted voltage reaches `critical_volts`; NaN as above.
  double seconds_to(double critical_volts) const noexcept;

 private:
  struct Sample {
    Time t;
    double volts;
    double amps;
  };
  double mean_amps() const noexcept;

  std::chrono::nanoseconds max_gap_;
  std::deque<Sample> window_;
};

}  // namespace pmu::energy
