#include "pmuctl/verbs/alarm_sample.hpp"

#include "pmuctl/verbs/alarm_names.hpp"

namespace pmu::tools {
namespace {

AlarmStatus status_of(pmu::v5::AlarmState s) {
  switch (s) {
    case pmu::v5::ALARM_ACTIVE_UNACKNOWLEDGED: return AlarmStatus::ActiveUnacknowledged;
    case pmu::v5::ALARM_ACTIVE_ACKNOWLEDGED: return AlarmStatus::ActiveAcknowledged;
    case pmu::v5::ALARM_CLEARED_UNACKNOWLEDGED: return AlarmStatus::ClearedUnacknowledged;
    case pmu::v5::ALARM_NORMAL: break;
  }
  return AlarmStatus::Normal;
}

}  // namespace

AlarmEntry alarm_entry_of(const pmu::v5::Alarm& a) {
  AlarmEntry e;
  e.vehicle = a.vehicle().to_string();
  e.bus = a.bus().to_string();
  e.kind = alarm_source_name(a.kind());
  e.device = a.device();
  e.code = a.code().to_string();
  e.critical = a.severity() == pmu::v5::SEVERITY_CRITICAL;
  e.state = status_of(a.state());
  e.value = a.value();
  e.limit = a.limit();
  e.since = a.since();
  e.message = a.message().to_string();
  return e;
}

bool selected(const GlobalOptions& o, const AlarmEntry& a) {
  return (!o.vehicle || *o.vehicle == a.vehicle) && (o.bus.empty() || o.bus == a.bus) &&
         (!o.address || (a.kind == "pmu" && *o.address == a.device));
}

}  // namespace pmu::tools
