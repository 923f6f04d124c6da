#pragma once
// The time integral of a power over samples that come at irregular intervals (trapezoid
// rule). An interval longer than `max_gap`, one that ends or starts on a sample of unknown
// power (NaN), and a sample at or before the one before add nothing: across a gap the
// power is not known, and guessing it would be worse than leaving it out. integrated_s()
// says how much time the integral covers.

#include <chrono>
#include <optional>

#include "pmu/energy/figures.hpp"

namespace pmu::energy {

class EnergyIntegral {
 public:
  // `max_gap` > 0: the longest interval still integrated (the tracker gives the device's
  // STALE time: its period x timeouts.stale_periods).
  explicit EnergyIntegral(std::chrono::nanoseconds max_gap) noexcept : max_gap_(max_gap) {}

  void add(Time t, double watts) noexcept;
  double joules() const noexcept { return joules_; }
  double watt_hours() const noexcept { return joules_ / 3600.0; }
  double integrated_s() const noexcept { return integrated_s_; }

 private:
  std::chrono::nanoseconds max_gap_;
  std::optional<Time> last_t_;
  double last_w_ = kUnknown;
  double joules_ = 0;
  double integrated_s_ = 0;
};

}  // namespace pmu::energy
