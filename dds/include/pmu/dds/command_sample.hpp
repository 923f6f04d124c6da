#pragma once
// A pmu::v5::Command as a client writes it and its reply's result as the service means it
// (interface.md 2.1, 2.3, 2.4), shared by pmuctl's blocking channel and pmu-mavlink's polled
// one, so both put an action into the same fields and name their requests the same way.
// Pure but for request_id and epoch_ns_at, which read the clocks and the host name.

#include <chrono>
#include <cstdint>
#include <string>
#include <string_view>

#include "pmu/command/command.hpp"
#include "pmu/idl/command.h"

namespace pmu::dds {

// "COMPLETED", "REJECTED", ...: the service's names of its results.
const char* result_name(pmu::v5::CommandResult r);
// The service's result a reply carries; a value outside the enum (a newer service's) is
// FAILED: not done, as far as this client can tell.
service::CommandResult command_result(pmu::v5::CommandResult r) noexcept;

// "PROGRAM-HOST-PID-": what every request id of this process starts with, the host name cut
// to `host_bytes`.
std::string request_id_prefix(std::string_view program, std::size_t host_bytes = 24);
// A request id unique per sender: the prefix (host cut to 24 bytes) and the nanoseconds of
// the Unix epoch now.
std::string request_id(std::string_view program);

// `deadline` (steady) as ns since the Unix epoch: a request's expires_at (interface.md
// 2.3), so the service sends nothing of it once its client has given up on it
// (docs/safety.md H9).
std::uint64_t epoch_ns_at(std::chrono::steady_clock::time_point deadline);

// The kind and arguments of `action` in `c`: kind, parameter, value, outputs, enable, groups
// (a SET_PARAMETER's value in the parameter's unit, which the service turns back into the
// same wire value). The target, id, expiry and confirm are the caller's.
void put_action(const service::CommandAction& action, pmu::v5::Command& c);

}  // namespace pmu::dds
