#include "pmu/energy/pmu_energy.hpp"

#include <cmath>

namespace pmu::energy {

PmuEnergy::PmuEnergy(CriticalVoltages critical, std::chrono::nanoseconds max_gap) noexcept
    : critical_(critical),
      max_gap_(max_gap),
      out_of_a_(max_gap),
      out_of_b_(max_gap),
      trend_a_(max_gap),
      trend_b_(max_gap) {}

bool PmuEnergy::fresh(const std::optional<Time>& at, Time now) const noexcept {
  return at && now - *at <= max_gap_ && *at - now <= max_gap_;
}

void PmuEnergy::on_voltages(Time received, const codec::Voltages& v) noexcept { volts_ = {received, v}; }

void PmuEnergy::on_currents(Time received, const codec::Currents& c) {
  amps_ = {received, c};
  // Integrated on each currents sample: the current moves with the load, the voltage slowly.
  const bool v = fresh(volts_.at, received);
  const double va = v ? volts_.value.battery_a : kUnknown;
  const double vb = v ? volts_.value.battery_b : kUnknown;
  out_of_a_.add(received, -(va * c.battery_a));
  out_of_b_.add(received, -(vb * c.battery_b));
  trend_a_.add(received, va, c.battery_a);
  trend_b_.add(received, vb, c.battery_b);
}

Figures PmuEnergy::figures(Time now) const noexcept {
  Figures f;
  const bool v = fresh(volts_.at, now), a = fresh(amps_.at, now);
  auto power = [&](double codec::Voltages::*vf, double codec::Currents::*af) {
    return v && a ? volts_.value.*vf * amps_.value.*af : kUnknown;
  };
  f.avionics_power = power(&codec::Voltages::avionics, &codec::Currents::avionics);
  f.output_28v_power = power(&codec::Voltages::output_28v, &codec::Currents::output_28v);
  f.payload_power = power(&codec::Voltages::payload, &codec::Currents::payload);
  f.servo_power = power(&codec::Voltages::servo, &codec::Currents::servo);
  f.battery_a.power = power(&codec::Voltages::battery_a, &codec::Currents::battery_a);
  f.battery_b.power = power(&codec::Voltages::battery_b, &codec::Currents::battery_b);
  f.generator_power =
      f.avionics_power + f.output_28v_power + f.payload_power + f.servo_power + f.battery_a.power + f.battery_b.power;
  f.battery_a.used_wh = out_of_a_.watt_hours();
  f.battery_b.used_wh = out_of_b_.watt_hours();
  f.battery_a.integrated_s = out_of_a_.integrated_s();
  f.battery_b.integrated_s = out_of_b_.integrated_s();
  f.battery_a.critical_voltage = critical_.battery_a;
  f.battery_b.critical_voltage = critical_.battery_b;
  f.battery_a.endurance_s = a ? trend_a_.seconds_to(critical_.battery_a) : kUnknown;
  f.battery_b.endurance_s = a ? trend_b_.seconds_to(critical_.battery_b) : kUnknown;
  return f;
}

std::optional<Figures> PmuEnergy::report(Time now) noexcept {
  if (!volts_.at || !amps_.at) return std::nullopt;
  // A clock stepped back reports at once and counts the period from there.
  if (last_report_ && now >= *last_report_ && now - *last_report_ < kReportPeriod) return std::nullopt;
  last_report_ = now;
  return figures(now);
}

}  // namespace pmu::energy
