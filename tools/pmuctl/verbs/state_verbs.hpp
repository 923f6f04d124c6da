#pragma once
// pmuctl's state verbs (interface.md section 3.2): watch, list, info, health, config get.
// Each returns the process exit status; messages a person can act on go to stderr
// ("no pmu-service on domain 0", "device 7 not seen on can0").

#include <chrono>
#include <cstdint>
#include <optional>
#include <string>

#include "pmu/config/network_settings.hpp"
#include "pmu/dds/dds_context.hpp"
#include "pmu/security/security_files.hpp"

namespace pmu::tools {

class ContextPool;  // context_lease.hpp

struct GlobalOptions {
  int domain = 0;
  // --vehicle / $PMU_VEHICLE. Readers: only that vehicle, or every vehicle when absent.
  // Commands: that vehicle, or the unnamed vehicle ("") when absent.
  std::optional<std::string> vehicle;
  std::string bus;                      // empty: every bus
  std::optional<std::uint16_t> address; // empty: every device
  bool json = false;
  bool low_rate = false;                // watch: the pmu/low_rate/* topics
  std::optional<double> timeout;        // s; verbs have their own default
  std::string qos_file;                 // empty: the installed qos.xml
  pmu::dds::SecurityFiles security;     // empty: no DDS-Security (--security-dir/--identity)
  pmu::dds::ResolvedNetwork network;    // discovery and interfaces (--peer, --discovery-server, --interface)
  bool no_agent = false;                // --no-agent: never through `pmuctl agent`
  // The end of the caller's wait, fixed when the call began (--timeout or the verb's default
  // from then): a verb waits for the service until then, a command sent expires then
  // (interface.md 2.3 expires_at), and a call `pmuctl agent` serves keeps its caller's,
  // however long it waited for a worker (docs/safety.md H9). Unset: from the verb's start.
  std::optional<std::chrono::steady_clock::time_point> deadline;
  std::uint64_t deadline_ns = 0;        // the same, in ns since the Unix epoch (0: unset)
  // Set while `pmuctl agent` serves the call: the verbs borrow its participants
  // (context_lease.hpp). Null for a call of its own.
  ContextPool* pool = nullptr;
};

// The end of the call's wait: o.deadline, else --timeout or `default_timeout` s from now.
std::chrono::steady_clock::time_point wait_end(const GlobalOptions& o, double default_timeout);

// The partitions of pmuctl's participant for these options (pmu/config/vehicle.hpp).
pmu::dds::Partitions partitions_for(const GlobalOptions& o);
// "uav1/can0/1", or "can0/1" for the unnamed vehicle.
std::string device_label(const std::string& vehicle, const std::string& bus, std::uint16_t address);

int run_watch(const GlobalOptions& o, long count);
int run_list(const GlobalOptions& o);
int run_info(const GlobalOptions& o);
int run_health(const GlobalOptions& o);
int run_config_get(const GlobalOptions& o, const std::string& parameter);

}  // namespace pmu::tools
