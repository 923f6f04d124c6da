#pragma once
// The start-up check that a loaded QoS profile holds the declared capacity (capacity.hpp):
// a misedited qos.xml is a clear start-up error instead of instances silently dropped later.

#include <fastdds/dds/core/policy/QosPolicies.hpp>
#include <string>

namespace pmu::dds {

enum class EndpointKind { Writer, Reader };

// Empty when `limits` and `history` hold what profile `profile` (telemetry, state, command)
// must hold for a writer or reader; else what falls short and what it must be, e.g.
// "max_instances 10 < 256 (PMUs per service, pmu::dds::kMaxDevicesPerService)".
// Profiles other than the contract's three are not checked.
std::string capacity_shortfall(const std::string& profile, EndpointKind kind,
                               const eprosima::fastdds::dds::ResourceLimitsQosPolicy& limits,
                               const eprosima::fastdds::dds::HistoryQosPolicy& history);

}  // namespace pmu::dds
