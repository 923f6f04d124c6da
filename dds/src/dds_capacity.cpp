#include "pmu/dds/dds_capacity.hpp"

#include <algorithm>
#include <cstdint>

#include "pmu/dds_settings/capacity.hpp"
#include "pmu/idl/topics.hpp"

namespace pmu::dds {
namespace {

using namespace eprosima::fastdds::dds;

struct Need {
  std::size_t instances;
  std::size_t per_instance;  // also the least KEEP_LAST depth
  const char* why;
};

std::string short_of(const char* field, std::int32_t have, std::size_t need, const char* why) {
  if (have > 0 && static_cast<std::size_t>(have) >= need) return {};
  return std::string(field) + " " + std::to_string(have) + " < " + std::to_string(need) + " (" + why + ")";
}

}  // namespace

std::string capacity_shortfall(const std::string& profile, EndpointKind kind, const ResourceLimitsQosPolicy& limits,
                               const HistoryQosPolicy& history) {
  Need need{};
  if (profile == qos_profiles::kTelemetry || profile == qos_profiles::kState) {
    need = kind == EndpointKind::Writer
               ? Need{kMaxDevicesPerService, 1, "PMUs per service, pmu::dds::kMaxDevicesPerService"}
               : Need{kFleetDevices, 1, "PMUs of a fleet, pmu::dds::kFleetDevices"};
  } else if (profile == qos_profiles::kAlarms) {
    need = kind == EndpointKind::Writer
               ? Need{kMaxAlarmsPerService, 1, "alarms per service, pmu::dds::kMaxAlarmsPerService"}
               : Need{kFleetAlarms, 1, "alarms of a fleet, pmu::dds::kFleetAlarms"};
  } else if (profile == qos_profiles::kRole) {
    need = kind == EndpointKind::Writer
               ? Need{kRoleWriterInstances, 1, "an instance's own name, pmu::dds::kRoleWriterInstances"}
               : Need{kFleetServices, 1, "service instances of a fleet, pmu::dds::kFleetServices"};
  } else if (profile == qos_profiles::kCommand) {
    // pmu/command and pmu/command_reply have no key: one instance holds the whole queue.
    need = Need{1, kCommandQueueDepth, "commands queued, pmu::dds::kCommandQueueDepth"};
  } else {
    return {};
  }
  const std::size_t depth =
      history.kind == KEEP_LAST_HISTORY_QOS ? static_cast<std::size_t>(std::max(history.depth, 1)) : need.per_instance;
  // Every instance's KEEP_LAST history must fit in max_samples at once.
  const std::size_t samples = need.instances * std::max(depth, need.per_instance);
  for (auto s :
       {short_of("max_instances", limits.max_instances, need.instances, need.why),
        short_of("max_samples_per_instance", limits.max_samples_per_instance, need.per_instance, need.why),
        short_of("max_samples", limits.max_samples, samples, need.why),
        history.kind == KEEP_LAST_HISTORY_QOS ? short_of("history depth", history.depth, need.per_instance, need.why)
                                              : std::string()})
    if (!s.empty()) return s;
  return {};
}

}  // namespace pmu::dds
