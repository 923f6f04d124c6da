#include "pmu/energy/endurance.hpp"

#include <algorithm>
#include <cmath>

namespace pmu::energy {

double VoltageTrendEndurance::mean_amps() const noexcept {
  double sum = 0;
  for (const auto& s : window_) sum += s.amps;
  return window_.empty() ? kUnknown : sum / static_cast<double>(window_.size());
}

void VoltageTrendEndurance::add(Time t, double volts, double amps) {
  if (std::isnan(volts) || std::isnan(amps)) {
    window_.clear();
    return;
  }
  if (!window_.empty()) {
    if (t == window_.back().t) return;
    const double mean = mean_amps();
    if (t < window_.back().t || t - window_.back().t > max_gap_ ||
        std::abs(amps - mean) > std::max(kLoadStep, 0.25 * std::abs(mean)))
      window_.clear();
  }
  window_.push_back({t, volts, amps});
  while (t - window_.front().t > kWindow) window_.pop_front();
}

double VoltageTrendEndurance::seconds_to(double critical_volts) const noexcept {
  if (std::isnan(critical_volts) || window_.size() < 3) return kUnknown;
  if (window_.back().t - window_.front().t < kMinSpan) return kUnknown;
  if (!(mean_amps() < -kMinDischarge)) return kUnknown;
  // Least squares on times relative to the newest sample, so the intercept is the fitted
  // voltage now and the sums stay small.
  const Time now = window_.back().t;
  double n = 0, sx = 0, sy = 0, sxx = 0, sxy = 0;
  for (const auto& s : window_) {
    const double x = std::chrono::duration<double>(s.t - now).count();
    n += 1;
    sx += x;
    sy += s.volts;
    sxx += x * x;
    sxy += x * s.volts;
  }
  const double denominator = n * sxx - sx * sx;
  if (!(denominator > 0)) return kUnknown;
  const double slope = (n * sxy - sx * sy) / denominator;
  const double span = std::chrono::duration<double>(now - window_.front().t).count();
  if (!(-slope * span >= kMinFall)) return kUnknown;
  const double fitted_now = (sy - slope * sx) / n;
  if (fitted_now <= critical_volts) return 0;
  return (fitted_now - critical_volts) / -slope;
}

}  // namespace pmu::energy
