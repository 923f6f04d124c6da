#pragma once
// One participant that sends pmu::v5::Commands to one vehicle's service and takes their
// replies (interface.md 2.1, 2.4): `pmuctl` command verbs send one, `config apply` a series
// over the same participant, so a change of ten settings costs one discovery, not ten.
//
// Lifetime: owns its participant, or borrows one of `pmuctl agent` (context_lease.hpp); the readers and writer it hands out live as long as it.
// Threads: the verb's thread only.

#include <chrono>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "pmu/dds/command_sample.hpp"
#include "pmu/dds/dds_context.hpp"
#include "pmu/idl/command.h"
#include "pmuctl/verbs/command_verbs.hpp"
#include "pmuctl/call/context_lease.hpp"

namespace pmu::tools {

// "COMPLETED", "REJECTED", ...: the service's names of its results.
using pmu::dds::result_name;

// A request id unique per sender: "pmuctl-HOST-PID-NANOSECONDS".
inline std::string request_id() { return pmu::dds::request_id("pmuctl"); }

// Finds the PMU a command is for: --bus/--address when both are given, else the only PMU
// (Health.kind: batteries and MPPTs take no commands) the service of `vehicle` knows.
// nullopt when found; else the exit status, after saying why in words a person can act on.
// The vehicle is never guessed: a command names --vehicle, or goes to the unnamed vehicle.
std::optional<int> resolve_target(const GlobalOptions& o, const std::string& vehicle, pmu::dds::DdsContext& dds,
                                  std::chrono::steady_clock::time_point deadline, std::string& bus,
                                  std::uint16_t& address);

// Waits until the service's request reader and reply writer are matched: a request written
// before would be lost, a reply sent before would never be seen. nullopt when matched.
std::optional<int> wait_for_match(const GlobalOptions& o, pmu::dds::DdsContext& dds,
                                  eprosima::fastdds::dds::DataWriter& writer,
                                  eprosima::fastdds::dds::DataReader& replies, const std::string& vehicle,
                                  std::chrono::steady_clock::time_point deadline, const char* accepts);

// In a call `pmuctl agent` serves (o.pool): makes each vehicle's command writer and reply
// reader, which stay matched in its partitions while idle (DdsContext::reuse_endpoints), so
// the first command to a vehicle a `list` has shown waits for no discovery across the link:
// over a radio link each lost announcement of that discovery costs a second. Their matching
// goes on after the call. Endpoints DDS refuses (an identity not allowed to command) are
// left to a command to report, and the worker does not try again. Nothing for a call of
// its own.
void open_command_channels(const GlobalOptions& o, const std::vector<std::string>& vehicles);

// `deadline`, the end of pmuctl's own wait, as ns since the Unix epoch: a request's
// expires_at (interface.md 2.3). The service sends nothing of a request after it, so nothing
// is carried out once pmuctl has given up on it (docs/safety.md H9).
using pmu::dds::epoch_ns_at;

class CommandChannel {
 public:
  using Clock = std::chrono::steady_clock;
  explicit CommandChannel(const GlobalOptions& o);

  pmu::dds::DdsContext& dds() { return dds_; }
  const std::string& vehicle() const { return vehicle_; }

  // How open() finds the PMU: resolve_target; or, in a call `pmuctl agent` serves, first the
  // PMU its worker found for the same vehicle and options before (TargetMemory), which a
  // caller that reads nothing more of the device takes; or none, for a broadcast.
  enum class Find { Resolve, MayRecall, Broadcast };
  // The PMU and the matched endpoints. nullopt when ready to send; else the exit status,
  // after saying why.
  std::optional<int> open(Clock::time_point deadline, std::string& bus, std::uint16_t& address,
                          Find find = Find::Resolve);

  struct Outcome {
    std::string request_id;
    std::optional<pmu::v5::CommandReply> reply;  // the final reply; nullopt: none within the timeout
    bool written = true;                         // false: DDS refused the first write
  };
  // Sends one command and waits for its final reply, resending with the same id after 1 s
  // without a reply (never executed twice: interface.md 2.4). Each IN_PROGRESS reply is
  // printed on stderr and keeps the wait open 3 s more than `timeout` would. The command's
  // expires_at is `expires_at_ns` when not 0 (the end of its caller's wait), else `timeout`
  // from now.
  Outcome send(const CommandSpec& spec, const std::string& bus, std::uint16_t address, double timeout,
               std::uint64_t expires_at_ns = 0);

  // True when open() took a remembered PMU and `out` is the service's answer that it has no
  // such device (not executed): the PMU is forgotten, and open() finds it afresh.
  bool recalled_target_gone(const Outcome& out, const std::string& bus, std::uint16_t address);

 private:
  TargetQuery query() const { return {vehicle_, options_.bus, options_.address}; }

  const GlobalOptions& options_;
  std::string vehicle_;
  bool recalled_ = false;  // open() took the PMU from the agent's TargetMemory
  ContextLease lease_;
  pmu::dds::DdsContext& dds_;
  eprosima::fastdds::dds::DataReader& replies_;
  eprosima::fastdds::dds::DataWriter& writer_;
};

}  // namespace pmu::tools
