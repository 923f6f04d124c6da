#include "pmuctl/call/context_lease.hpp"

#include <filesystem>

#include "pmu/idl/topics.hpp"
#include "pmuctl/verbs/state_verbs.hpp"

namespace pmu::tools {
namespace {

std::unique_ptr<pmu::dds::DdsContext> make_context(const GlobalOptions& o, const std::string& name,
                                                   const pmu::dds::Partitions& partitions,
                                                   pmu::dds::Transport transport = pmu::dds::Transport::Default) {
  return std::make_unique<pmu::dds::DdsContext>(o.domain, o.qos_file, name, o.security, transport, o.network,
                                                partitions);
}

bool same_security(const pmu::dds::SecurityFiles& a, const pmu::dds::SecurityFiles& b) {
  return a.identity_ca == b.identity_ca && a.identity_certificate == b.identity_certificate &&
         a.private_key == b.private_key && a.permissions_ca == b.permissions_ca && a.governance == b.governance &&
         a.permissions == b.permissions;
}

bool same_network(const pmu::dds::ResolvedNetwork& a, const pmu::dds::ResolvedNetwork& b) {
  // The summary names the mode, every peer or server and every interface address.
  return a.mode == b.mode && a.summary == b.summary && a.interface_addresses == b.interface_addresses;
}

}  // namespace

ContextPool::ContextPool(const GlobalOptions& settings) : settings_(settings) { settings_.pool = nullptr; }

pmu::dds::DdsContext& ContextPool::context(const std::string& participant_name,
                                           const pmu::dds::Partitions& partitions) {
  auto& slot = contexts_[participant_name];
  if (!slot) {
    try {
      // UDP alone, no shared memory: a worker killed (and replaced) leaves its shared-memory
      // port behind, with a reader slot nobody empties, and Fast DDS 2.9 gives a replacement
      // that port again (the same participant id once the dead one's UDP port is free): what
      // a service on this host sends it there would never arrive, and the replacement would
      // answer "no pmu-service" while the service runs (docs/safety.md H6). The aircraft are
      // on other hosts anyway.
      slot = make_context(settings_, participant_name, partitions, pmu::dds::Transport::UdpOnly);
      // Command endpoints carry only a call's requests and the replies to them: left matched
      // in their vehicle's partitions, the next command to it finds them matched.
      slot->reuse_endpoints({qos_profiles::kCommand});
    } catch (...) {
      contexts_.erase(participant_name);
      throw;
    }
  } else if (!slot->set_partitions(partitions)) {
    throw pmu::dds::DdsError("the agent's participant cannot move to this call's partitions");
  }
  return *slot;
}

std::string effective_qos_file(const std::string& qos_file) {
  const std::string file = qos_file.empty() ? pmu::dds::default_qos_file() : qos_file;
  if (file.empty()) return file;
  std::error_code ec;
  const auto path = std::filesystem::weakly_canonical(std::filesystem::absolute(file, ec), ec);
  return ec ? file : path.string();
}

bool same_dds_settings(const GlobalOptions& o, const GlobalOptions& agent) {
  return o.domain == agent.domain && effective_qos_file(o.qos_file) == effective_qos_file(agent.qos_file) &&
         same_security(o.security, agent.security) && same_network(o.network, agent.network);
}

ContextLease::ContextLease(const GlobalOptions& o, const std::string& participant_name)
    : owned_(o.pool ? nullptr : make_context(o, participant_name, partitions_for(o))),
      context_(o.pool ? &o.pool->context(participant_name, partitions_for(o)) : owned_.get()),
      mark_(context_->endpoint_mark()) {}

ContextLease::~ContextLease() {
  if (!owned_) context_->delete_endpoints_since(mark_);
}

}  // namespace pmu::tools
