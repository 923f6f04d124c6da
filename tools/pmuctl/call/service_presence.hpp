#pragma once
// What a verb that got nothing says: whether no pmu-service is on the domain at all (exit 3:
// nothing answered) or only services of other vehicles are (exit 2: no such target, with the
// vehicles there are). A participant in one vehicle's partitions never matches another
// vehicle's writers, so the answer comes from discovery (DdsContext::remote_writers).
//
// A service of another contract (contract_names.hpp) is never matched either: its type names
// differ. Discovery still reports its writers, so the verb says which contract it found
// instead of "no pmu-service".
//
// Call from the verb's thread, with the DdsContext the verb used (it must still be open).

#include <cstddef>
#include <fastdds/dds/subscriber/DataReader.hpp>
#include <map>
#include <set>
#include <string>

#include "pmu/dds/dds_context.hpp"
#include "pmuctl/call/global_options.hpp"

namespace pmu::tools {

// The vehicles whose pmu-service announced a health writer of this pmuctl's contract ("" is
// the unnamed vehicle).
std::set<std::string> vehicles_on_domain(const pmu::dds::DdsContext& dds);

// The services of other contracts discovery reported: contract -> their vehicles.
std::map<int, std::set<std::string>> other_contracts_on_domain(const pmu::dds::DdsContext& dds);

// "pmu-service of contract v3 (or older) (vehicles: (unnamed), uav2); this pmuctl reads
// contract v4 (docs/interface.md section 10)", or "" for none.
std::string other_contracts_text(const std::map<int, std::set<std::string>>& others);

// "; vehicles seen: (unnamed), uav1 (choose one with --vehicle)", or "" for none.
std::string vehicles_seen_text(const std::set<std::string>& vehicles);

// The writers of `topic` a state verb waits for (state_settle.hpp): those `reader` matched,
// plus the services discovered whose writer of it discovery has not reported yet.
std::size_t writers_expected(const pmu::dds::DdsContext& dds, eprosima::fastdds::dds::DataReader& reader,
                             const std::string& topic);

// "the unnamed vehicle" / "vehicle uav1".
std::string vehicle_text(const std::string& vehicle);

// Ends a verb whose readers matched no pmu-service: exit 3 when discovery found none of this
// contract on the domain (saying which other contracts' services it found), 2 when services
// of other vehicles than the one asked for are there.
int no_service(const GlobalOptions& o, const pmu::dds::DdsContext& dds);

// Ends a verb whose readers matched pmu-service writers none of which sent anything during
// the call: exit 3, "no pmu-service [of VEHICLE] on domain N", what a call on its own says
// when no service is there. A live service's state writers answer a reader that matches
// them at once (TRANSIENT_LOCAL), and its pmu/readiness at least once a second; a service
// killed or stopped answers nothing, yet a participant that knew it (the agent's workers)
// still matches its writers until its DDS lease ends, and must not take that silence for
// an empty state, no alarm or no device (docs/safety.md H6).
int nothing_heard(const GlobalOptions& o);

}  // namespace pmu::tools
