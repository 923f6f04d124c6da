#include "pmuctl/verbs/alarm_names.hpp"

namespace pmu::tools {

const char* alarm_source_name(pmu::v5::AlarmSource k) noexcept {
  switch (k) {
    case pmu::v5::SOURCE_BATTERY: return "battery";
    case pmu::v5::SOURCE_MPPT: return "mppt";
    case pmu::v5::SOURCE_BUS: return "bus";
    case pmu::v5::SOURCE_PMU: break;
  }
  return "pmu";
}

const char* alarm_state_name(pmu::v5::AlarmState s) noexcept {
  switch (s) {
    case pmu::v5::ALARM_ACTIVE_UNACKNOWLEDGED: return "ACTIVE_UNACKNOWLEDGED";
    case pmu::v5::ALARM_ACTIVE_ACKNOWLEDGED: return "ACTIVE_ACKNOWLEDGED";
    case pmu::v5::ALARM_CLEARED_UNACKNOWLEDGED: return "CLEARED_UNACKNOWLEDGED";
    case pmu::v5::ALARM_NORMAL: break;
  }
  return "NORMAL";
}

}  // namespace pmu::tools
