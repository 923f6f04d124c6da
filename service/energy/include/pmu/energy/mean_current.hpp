#pragma once
// The filtered current of a battery whose BMS reports its state of charge: the time-weighted
// mean of the current over a sliding window (kMeanWindow, the window the PMU batteries'
// voltage trend uses), by the trapezoid rule over the samples' receive times. A window mean
// rather than an exponential filter: it is the charge the battery actually gave over the last
// five minutes divided by their length, so "endurance at the present draw" means the draw of
// a stated stretch of time, and a load that ended more than a window ago is gone from it
// entirely rather than fading. Load steps are kept in the mean (unlike the voltage trend,
// where a step's IR drop would read as a slope): the draw is measured, not inferred.
//
// A gap longer than `max_gap`, a current not known (NaN) and a clock stepped back restart the
// window: across a gap the draw is not known. With one sample, or samples at one time, the
// mean is that sample's current.
//
// Pure: no clock, no I/O. Not thread-safe: the owner serialises calls.

#include <chrono>
#include <deque>

#include "pmu/energy/figures.hpp"

namespace pmu::energy {

inline constexpr std::chrono::seconds kMeanWindow{300};

class MeanCurrent {
 public:
  // `max_gap` > 0: the longest interval between samples that keeps the window.
  explicit MeanCurrent(std::chrono::nanoseconds max_gap) noexcept : max_gap_(max_gap) {}

  void add(Time t, double amps);
  // A, NaN while the window is empty.
  double mean() const noexcept;
  // s from the window's first sample to its last.
  double span_s() const noexcept;

 private:
  struct Sample {
    Time t;
    double amps;
  };
  std::chrono::nanoseconds max_gap_;
  std::deque<Sample> window_;
};

}  // namespace pmu::energy
