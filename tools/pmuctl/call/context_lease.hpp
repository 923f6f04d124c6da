#pragma once
// Where a verb's DDS participant comes from. A plain pmuctl call makes its own and deletes
// it when the verb ends. A call that `pmuctl agent` serves borrows one of the agent's
// long-lived participants instead: the aircraft have discovered it once, so over a radio
// link a call costs its few endpoints and their samples rather than a whole participant's
// discovery. The endpoints the verb made are parked when it ends and taken up again by a
// later call (DdsContext::reuse_endpoints says why they are not deleted).
//
// Lifetime: a ContextPool outlives every lease taken from it (the agent owns it for its
// whole run); a lease outlives every reference the verb took from its context.
// Threads: the verb's thread only; each of the agent's workers serves one call at a time.

#include <map>
#include <memory>
#include <string>
#include <vector>

#include "pmu/dds/dds_context.hpp"
#include "pmuctl/agent/target_memory.hpp"
#include "pmuctl/call/global_options.hpp"

namespace pmu::tools {

// The participant name of every verb's lease: an agent's worker serves all its calls with one
// participant of this name.
inline constexpr const char* kPmuctlParticipant = "pmuctl";

class ContextPool {
 public:
  // `settings`: the domain, QoS file, security files and network of every participant made.
  explicit ContextPool(const GlobalOptions& settings);
  ContextPool(const ContextPool&) = delete;
  ContextPool& operator=(const ContextPool&) = delete;

  // The participant of this name, made at its first use, its publisher and subscriber moved
  // to `partitions`: one participant serves every vehicle in turn, so the aircraft discover
  // one participant of the agent, once. Throws DdsError like DdsContext's constructor, and
  // when the partitions cannot be set.
  pmu::dds::DdsContext& context(const std::string& participant_name, const pmu::dds::Partitions& partitions);

  // The PMU each vehicle's commands went to (command_channel.hpp says when it is used).
  TargetMemory& targets() noexcept { return targets_; }

  // Whether DDS refused this pool's command endpoints once (an identity not allowed to
  // command): a list then no longer makes them ahead of a command (open_command_channels).
  bool commands_refused() const noexcept { return commands_refused_; }
  void refuse_commands() noexcept { commands_refused_ = true; }

 private:
  GlobalOptions settings_;
  TargetMemory targets_;
  bool commands_refused_ = false;
  std::map<std::string, std::unique_ptr<pmu::dds::DdsContext>> contexts_;
};

// The QoS file a participant made now would load (`qos_file`, else default_qos_file(), which
// reads $PMU_QOS_FILE), as an absolute path without symbolic links; empty when there is none.
// The agent resolves its own once at start-up: during a call the environment is the caller's.
std::string effective_qos_file(const std::string& qos_file);

// True when a call with options `o` would make the same participants as the pool of
// `agent`: the same domain, QoS file (effective_qos_file: the caller's $PMU_QOS_FILE counts),
// security files and network. Anything else (another domain, QoS file, identity or discovery
// server) is not the agent's to serve.
bool same_dds_settings(const GlobalOptions& o, const GlobalOptions& agent);

class ContextLease {
 public:
  // From o.pool when set, else a participant of its own; partitions_for(o).
  ContextLease(const GlobalOptions& o, const std::string& participant_name);
  ~ContextLease();
  ContextLease(const ContextLease&) = delete;
  ContextLease& operator=(const ContextLease&) = delete;

  pmu::dds::DdsContext& operator*() noexcept { return *context_; }
  pmu::dds::DdsContext* operator->() noexcept { return context_; }

 private:
  std::unique_ptr<pmu::dds::DdsContext> owned_;
  pmu::dds::DdsContext* context_;
  pmu::dds::DdsContext::EndpointMark mark_;
};

}  // namespace pmu::tools
