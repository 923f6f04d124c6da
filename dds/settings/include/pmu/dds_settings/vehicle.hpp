#pragma once
// Which vehicle a service belongs to, and how that shows on DDS (docs/interface.md 7.1).
//
// Every sample carries its vehicle as the first key, so a ground station that reads every
// vehicle tells them apart, and two aircraft with the same bus names and CAN addresses are
// different instances. Each service's publisher and subscriber sit in the DDS partition named
// after its vehicle, so a command written in one vehicle's partition reaches only that
// vehicle's service, and DDS-Security permissions, which grant partitions, can confine an
// identity to some vehicles. The unnamed vehicle ("") uses the default partition: a single
// aircraft needs no configuration.

#include <cstddef>
#include <string>
#include <string_view>
#include <vector>

namespace pmu::dds {

inline constexpr std::size_t kMaxVehicleNameLength = 15;  // string<15> in the IDL

// Why `name` cannot be a vehicle name, or "" when it can: 0..15 bytes of letters,
// digits, '_', '-' and '.'. Partition matching treats '*', '?', '[' and '\' as patterns, so
// they are refused: a vehicle name must name one vehicle.
std::string vehicle_name_problem(std::string_view name);

// The partitions of a service (and of a client that addresses one vehicle): the vehicle's
// name, or none (the default partition) for the unnamed vehicle.
std::vector<std::string> vehicle_partitions(const std::string& vehicle);

// The partitions of a reader that sees every vehicle: the default partition and every named
// one (a pattern that matches every vehicle name and nothing else pmu-dds uses). Fast DDS
// matches a reader's pattern only with writers that name a partition, hence "".
std::vector<std::string> every_vehicle_partitions();

// True when a command writer's partitions are exactly those a client of `vehicle` uses. The
// service accepts commands only from such writers: a writer in partition "*" matches every
// vehicle's service at once (an identity granted "*", or any peer without security).
bool partitions_address_only(const std::vector<std::string>& writer_partitions, const std::string& vehicle);

}  // namespace pmu::dds
