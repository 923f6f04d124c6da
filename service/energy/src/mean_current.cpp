#include "pmu/energy/mean_current.hpp"

#include <cmath>

namespace pmu::energy {

void MeanCurrent::add(Time t, double amps) {
  if (std::isnan(amps)) {
    window_.clear();
    return;
  }
  if (!window_.empty()) {
    // A repeated time brings no new interval; the newest current stands for it.
    if (t == window_.back().t) {
      window_.back().amps = amps;
      return;
    }
    if (t < window_.back().t || t - window_.back().t > max_gap_) window_.clear();
  }
  window_.push_back({t, amps});
  while (t - window_.front().t > kMeanWindow) window_.pop_front();
}

double MeanCurrent::mean() const noexcept {
  if (window_.empty()) return kUnknown;
  double charge = 0;  // A s
  for (std::size_t i = 1; i < window_.size(); ++i) {
    const double dt = std::chrono::duration<double>(window_[i].t - window_[i - 1].t).count();
    charge += 0.5 * (window_[i].amps + window_[i - 1].amps) * dt;
  }
  const double span = span_s();
  return span > 0 ? charge / span : window_.back().amps;
}

double MeanCurrent::span_s() const noexcept {
  return window_.empty() ? 0 : std::chrono::duration<double>(window_.back().t - window_.front().t).count();
}

}  // namespace pmu::energy
