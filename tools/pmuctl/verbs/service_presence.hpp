#pragma once
// What a verb that got nothing says: whether no pmu-service is on the domain at all (exit 3:
// nothing answered) or only services of other vehicles are (exit 2: no such target, with the
// vehicles there are). A participant in one vehicle's partitions never matches another
// vehicle's writers, so the answer comes from discovery (DdsContext::remote_writers).
//
// Call from the verb's thread, with the DdsContext the verb used (it must still be open).

#include <set>
#include <string>

#include "pmu/dds/dds_context.hpp"
#include "pmuctl/verbs/state_verbs.hpp"

namespace pmu::tools {

// The vehicles whose pmu-service announced a health writer ("" is the unnamed vehicle).
std::set<std::string> vehicles_on_domain(const pmu::dds::DdsContext& dds);

// "; vehicles seen: (unnamed), uav1 (choose one with --vehicle)", or "" for none.
std::string vehicles_seen_text(const std::set<std::string>& vehicles);

// "the unnamed vehicle" / "vehicle uav1".
std::string vehicle_text(const std::string& vehicle);

// Ends a verb whose readers matched no pmu-service: exit 3 when discovery found none on the
// domain, 2 when services of other vehicles than the one asked for are there.
int no_service(const GlobalOptions& o, const pmu::dds::DdsContext& dds);

}  // namespace pmu::tools
