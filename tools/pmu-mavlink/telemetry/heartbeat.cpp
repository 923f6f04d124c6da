#include "telemetry/heartbeat.hpp"

namespace pmu::mavlink_bridge {

namespace nm = pmu::mavlink;

nm::Heartbeat heartbeat(ServiceReadiness readiness) {
  nm::Heartbeat m;
  m.type = nm::mav_type::kBattery;
  m.autopilot = nm::mav_autopilot::kInvalid;
  switch (readiness) {
    case ServiceReadiness::not_heard: m.system_status = nm::mav_state::kBoot; break;
    case ServiceReadiness::ready: m.system_status = nm::mav_state::kActive; break;
    case ServiceReadiness::not_ready: m.system_status = nm::mav_state::kStandby; break;
  }
  return m;
}

}  // namespace pmu::mavlink_bridge
