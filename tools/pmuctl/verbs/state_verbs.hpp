#pragma once
// pmuctl's state verbs (interface.md section 3.2): watch, list, info, health, config get.
// Each returns the process exit status; messages a person can act on go to stderr
// ("no pmu-service on domain 0", "device 7 not seen on can0").

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
  // Set while `pmuctl agent` serves the call: the verbs borrow its participants
  // (context_lease.hpp). Null for a call of its own.
  ContextPool* pool = nullptr;
};

// The partitions of pmuctl's participant for these options (service/vehicle.hpp).
pmu::dds::Partitions partitions_for(const GlobalOptions& o);
// "uav1/can0/1", or "can0/1" for the unnamed vehicle.
std::string device_label(const std::string& vehicle, const std::string& bus, std::uint16_t address);

int run_watch(const GlobalOptions& o, long count);
int run_list(const GlobalOptions& o);
int run_info(const GlobalOptions& o);
int run_health(const GlobalOptions& o);
int run_config_get(const GlobalOptions& o, const std::string& parameter);

}  // namespace pmu::tools
