#include "pmu/session/alarm_feed.hpp"

#include <spdlog/spdlog.h>

#include <limits>

namespace pmu::service {
namespace {

alarms::AlarmSet make_set(const std::string& who, alarms::DeviceKind kind, const alarms::DeviceSettings& settings) {
  auto set = alarms::AlarmSet::make(kind, settings);
  if (set) return std::move(*set);
  spdlog::error("{}: alarm settings refused ({}); the table's defaults apply", who, set.error());
  return std::move(*alarms::AlarmSet::make(kind));
}

}  // namespace

AlarmFeed::AlarmFeed(std::string bus, alarms::DeviceKind source, std::uint16_t device,
                     const alarms::DeviceSettings& settings, StateSink& sink)
    : bus_(std::move(bus)),
      source_(source),
      device_(device),
      sink_(sink),
      set_(make_set(bus_ + "/" + std::string(alarms::to_string(source)) + std::to_string(device), source, settings)) {}

void AlarmFeed::observe(alarms::Code code, double value, SteadyTime now, WallTime wall) {
  if (set_.observe(code, value, now)) changed(code, wall);
}

void AlarmFeed::observe_flag(alarms::Code code, bool set, SteadyTime now, WallTime wall) {
  if (set_.observe_flag(code, set, now)) changed(code, wall);
}

void AlarmFeed::tick(SteadyTime now, WallTime wall) {
  for (const auto code : set_.tick(now)) changed(code, wall);
}

alarms::AckResult AlarmFeed::acknowledge(alarms::Code code, SteadyTime now, WallTime wall) {
  const auto r = set_.acknowledge(code, now);
  if (r == alarms::AckResult::Acknowledged) changed(code, wall);
  return r;
}

void AlarmFeed::move_to(std::uint16_t device) {
  device_ = device;
  for (const auto* a : set_.not_normal()) report(*a);
}

void AlarmFeed::changed(alarms::Code code, WallTime wall) {
  since_[static_cast<std::size_t>(code)] = wall;
  if (const auto* a = set_.find(code)) report(*a);
}

void AlarmFeed::report(const alarms::Alarm& a) {
  AlarmReport r;
  r.bus = bus_;
  r.source = source_;
  r.device = device_;
  r.code = a.code();
  r.severity = a.severity();
  r.state = a.state();
  // A flag's input is 1 or 0, which says nothing the state does not.
  r.value =
      a.config().spec().condition == alarms::Condition::Flag ? std::numeric_limits<double>::quiet_NaN() : a.value();
  r.limit = a.limit();
  r.since = since_[static_cast<std::size_t>(a.code())];
  r.message = std::string(a.message());
  const auto level = a.state() == alarms::AlarmState::ActiveUnacknowledged
                         ? (a.severity() == alarms::Severity::Critical ? spdlog::level::err : spdlog::level::warn)
                         : spdlog::level::info;
  spdlog::log(level, "{}/{}{}: alarm {} {}: {}", bus_, alarms::to_string(source_), device_, alarms::to_string(a.code()),
              alarms::to_string(a.state()), a.message());
  sink_.on_alarm(r);
}

}  // namespace pmu::service
