#pragma once
// Receive times for the derived-energy tests (energy_test.cpp, bms_energy_test.cpp): seconds
// after a fixed wall-clock time, and NaN for a value not known.
#include <chrono>
#include <limits>

#include "pmu/energy/figures.hpp"

namespace pmu::energy::test_times {

inline constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
inline const Time t0 = Time{} + std::chrono::hours(24 * 365 * 56);  // a wall-clock time in 2026

inline Time at(double seconds) {
  return t0 + std::chrono::duration_cast<Time::duration>(std::chrono::duration<double>(seconds));
}

}  // namespace pmu::energy::test_times
