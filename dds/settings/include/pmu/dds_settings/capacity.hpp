#pragma once
// What pmu-dds is sized for, declared once. deploy/qos.xml's resource limits are derived from
// these numbers (its comments say which); DdsContext refuses at start-up a QoS profile that
// holds less (dds_capacity.hpp), and the config loader refuses more devices than a service
// may serve. Beyond these limits Fast DDS would drop instances without a word: its defaults
// (10 instances per writer and reader) once cut a 50-PMU service down to 10 in pmuctl.

#include <cstddef>

#include "pmu/alarms/alarm_table.hpp"

namespace pmu::dds {

// PMUs one pmu-service serves (configured plus discovered, all buses together): the
// instances of each of its telemetry and state writers.
inline constexpr std::size_t kMaxDevicesPerService = 256;
// Services one client (pmuctl, a mission computer) may see on its domain.
inline constexpr std::size_t kFleetServices = 64;
// Instances of each telemetry and state reader of a client: every PMU of the fleet.
inline constexpr std::size_t kFleetDevices = kMaxDevicesPerService * kFleetServices;
// Commands (and replies) queued per writer and reader: profile `command`'s KEEP_LAST depth,
// which a burst of 2,000 commands written at once does not overflow.
inline constexpr std::size_t kCommandQueueDepth = 4096;
// pmu/alarms: one instance per alarm of a device or bus that has ever left NORMAL; a device
// holds at most every code of the table.
inline constexpr std::size_t kMaxAlarmsPerService = kMaxDevicesPerService * alarms::kCodeCount;
inline constexpr std::size_t kFleetAlarms = kMaxAlarmsPerService * kFleetServices;
// pmu/role (profile `role`): a service instance writes one instance, its own name; a reader
// holds every instance of the fleet's services (kFleetServices).
inline constexpr std::size_t kRoleWriterInstances = 1;

}  // namespace pmu::dds
