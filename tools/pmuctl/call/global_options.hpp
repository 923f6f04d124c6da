#pragma once
// The options every pmuctl verb reads (pmuctl(1) "Global options"), checked and typed: what
// run_cli (main.cpp) hands each verb, and what `pmuctl agent` compares a call's DDS settings
// with (context_lease.hpp).

#include <chrono>
#include <cstdint>
#include <optional>
#include <string>

#include "pmu/dds_settings/network_settings.hpp"
#include "pmu/security/security_files.hpp"

namespace pmu::tools {

class ContextPool;  // context_lease.hpp

struct GlobalOptions {
  int domain = 0;
  // --vehicle / $PMU_VEHICLE. Readers: only that vehicle, or every vehicle when absent.
  // Commands: that vehicle, or the unnamed vehicle ("") when absent.
  std::optional<std::string> vehicle;
  std::string bus;                       // empty: every bus
  std::optional<std::uint16_t> address;  // empty: every device
  bool json = false;
  bool low_rate = false;              // watch: the pmu/low_rate/* topics
  std::optional<double> timeout;      // s; verbs have their own default
  std::string qos_file;               // empty: the installed qos.xml
  pmu::dds::SecurityFiles security;   // empty: no DDS-Security (--security-dir/--identity)
  pmu::dds::ResolvedNetwork network;  // discovery and interfaces (--peer, --discovery-server, --interface)
  bool no_agent = false;              // --no-agent: never through `pmuctl agent`
  // The end of the caller's wait, fixed when the call began (--timeout or the verb's default
  // from then): a verb waits for the service until then, a command sent expires then
  // (interface.md 2.3 expires_at), and a call `pmuctl agent` serves keeps its caller's,
  // however long it waited for a worker (docs/safety.md H9). Unset: from the verb's start.
  std::optional<std::chrono::steady_clock::time_point> deadline;
  std::uint64_t deadline_ns = 0;  // the same, in ns since the Unix epoch (0: unset)
  // Set while `pmuctl agent` serves the call: the verbs borrow its participants
  // (context_lease.hpp). Null for a call of its own.
  ContextPool* pool = nullptr;
};

}  // namespace pmu::tools
