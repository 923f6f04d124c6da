#pragma once
// The contract's types as XTypes type objects, so eProsima's dynamic-type tools (Fast DDS
// Monitor, PlotJuggler's Fast DDS plugin, DDS Record & Replay) can decode topics without our
// IDL (docs/interface.md 9.4).
//
// register_type_objects(): puts the TypeObject and TypeIdentifier of every type of idl/
// (fastddsgen -typeobject, idl/CMakeLists.txt) into Fast DDS's process-wide TypeObjectFactory.
// Fast DDS looks a writer's or reader's type up there by name when the endpoint is created
// (EDP::newLocalWriterProxyData in 2.9.1), so this must run before the first endpoint;
// DdsContext calls it before it creates its participant. Safe to call any number of times,
// from any thread.
//
// announce_type_object(type, enabled): what a TypeSupport of ours announces in discovery
// (call it after register_type_objects). Off unless configured (dds_type_objects): they add
// about 10 kB to the discovery traffic every joining participant gets from the simulated
// power system (27 kB instead of 17 kB, measured with tcpdump), and its largest discovery
// datagram grows from 7.0 kB to 16.9 kB, from 5 IP fragments to 12 at a 1500-byte MTU. Over
// a ground link with 10 % loss such a datagram arrives whole in 28 % of the tries instead of
// 59 %; with them on, the network lab's fleet scenario failed twice in two runs (a late
// pmuctl got no pmu/config in 30 s; gnd listed no vehicle in 90 s).
//
// Never the XTypes 1.2 TypeInformation (PID 0x75), which Fast DDS 2.9.1 sends by default:
// Eclipse Cyclone DDS 0.10.2 cannot parse Fast DDS 2.9.1's (its log: "invalid parameter list
// ... pid 75 (TYPE_INFORMATION) invalid") and drops the whole endpoint announcement, so it
// matches nothing of ours (measured with it on: the crossvendor client missed all 9 of its
// checks). The type object (PIDs 0x72 and 0x69, which other vendors skip) only when it is
// self-contained (type_object_is_self_contained): every Fast DDS 2.9.1 participant that does
// not know a type builds a DynamicType from each type object it discovers
// (PDP::check_and_notify_type_discovery), and for a member whose type is only named by its
// hash it drops the member (an enum: pmu::v5::Health's kind) or crashes in its receive thread
// (measured: a sequence of a struct, pmu::v5::BatteryCells' cells, SIGSEGV in
// TypeObjectFactory::get_sequence_identifier). A third party's Fast DDS 2.9 client without
// our type objects would be killed by discovering pmu/battery_cells.

#include <fastdds/dds/topic/TypeSupport.hpp>
#include <string>

namespace pmu::dds {

void register_type_objects();

// True when the registered complete type object of `type_name` is a struct whose members'
// types are all described by their identifiers alone (primitives, strings, and sequences or
// arrays of those): a DynamicType can be built from it with nothing else known. False for an
// unknown name.
bool type_object_is_self_contained(const std::string& type_name);

// `enabled` false: neither (Fast DDS 2.9.1 would otherwise send whatever is registered).
void announce_type_object(eprosima::fastdds::dds::TypeSupport& type, bool enabled);

}  // namespace pmu::dds
