#include "pmu/energy/bms_energy.hpp"

#include <cmath>

namespace pmu::energy {

BmsEnergy::BmsEnergy(BmsSettings settings, std::chrono::nanoseconds max_gap) noexcept
    : settings_(settings), max_gap_(max_gap), out_(max_gap), draw_(max_gap) {}

void BmsEnergy::on_sample(Time received, const BmsReading& reading) {
  latest_at_ = received;
  latest_ = reading;
  known_ = known_ || (!std::isnan(reading.voltage) && !std::isnan(reading.current));
  out_.add(received, -(reading.voltage * reading.current));
  draw_.add(received, reading.current);
}

BmsFigures BmsEnergy::figures(Time now) const noexcept {
  BmsFigures f;
  f.capacity_ah = settings_.capacity_ah;
  f.critical_state_of_charge = settings_.critical_state_of_charge;
  f.used_wh = out_.watt_hours();
  f.integrated_s = out_.integrated_s();
  const bool fresh = latest_at_ && now - *latest_at_ <= max_gap_ && *latest_at_ - now <= max_gap_;
  if (!fresh) return f;
  f.power = latest_.voltage * latest_.current;
  const double mean = draw_.mean();
  // NaN compares false: an unknown mean, charge, capacity or limit leaves the endurance NaN.
  if (!(mean < -kBmsMinDischarge) || !(settings_.capacity_ah > 0) || std::isnan(latest_.state_of_charge) ||
      std::isnan(settings_.critical_state_of_charge))
    return f;
  const double left_percent = latest_.state_of_charge - settings_.critical_state_of_charge;
  f.endurance_s = left_percent <= 0 ? 0 : left_percent / 100 * settings_.capacity_ah * 3600 / -mean;
  return f;
}

std::optional<BmsFigures> BmsEnergy::report(Time now) noexcept {
  if (!known_) return std::nullopt;
  // A clock stepped back reports at once and counts the period from there.
  if (last_report_ && now >= *last_report_ && now - *last_report_ < kReportPeriod) return std::nullopt;
  last_report_ = now;
  return figures(now);
}

}  // namespace pmu::energy
