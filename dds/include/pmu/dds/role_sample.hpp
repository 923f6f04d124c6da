#pragma once
// pmu/role both ways (interface.md 1.10, docs/design.md "Hot standby"): the holder's report as
// the contract's pmu::v5::RoleHeartbeat, and a received sample back as the role machine's
// plain values, for the service's role endpoint and pmuctl alike. The one place that reads the
// sample's enumerators: a value outside its literals (a hostile writer, a newer build) is a
// problem named, never a cast. Pure; any thread.

#include <string>

#include "pmu/idl/role.h"
#include "pmu/redundancy/role.hpp"

namespace pmu::dds {

// The sample an instance of vehicle `vehicle` writes for `report`.
pmu::v5::RoleHeartbeat role_heartbeat_sample(const std::string& vehicle, const redundancy::RoleReport& report);

// A received sample: its vehicle and report, or (`problem` not empty, `report` default) why it
// is not one ("role 9 is not an InstanceRole").
struct ReadRole {
  std::string vehicle;
  redundancy::RoleReport report;
  std::string problem;
  bool ok() const noexcept { return problem.empty(); }
};
ReadRole read_role_heartbeat(const pmu::v5::RoleHeartbeat& sample);

}  // namespace pmu::dds
