#include "pmu/energy/energy_integral.hpp"

#include <cmath>

namespace pmu::energy {

void EnergyIntegral::add(Time t, double watts) noexcept {
  // Receive times are the wall clock's: a second sample at the same time adds nothing, and
  // one before the last (the clock stepped back) starts the integral again from it, as a gap
  // does, rather than integrating backwards or stopping until the clock catches up.
  if (last_t_ && t == *last_t_) return;
  if (last_t_ && t > *last_t_ && t - *last_t_ <= max_gap_ && !std::isnan(watts) && !std::isnan(last_w_)) {
    const double dt = std::chrono::duration<double>(t - *last_t_).count();
    joules_ += 0.5 * (watts + last_w_) * dt;
    integrated_s_ += dt;
  }
  last_t_ = t;
  last_w_ = watts;
}

}  // namespace pmu::energy
