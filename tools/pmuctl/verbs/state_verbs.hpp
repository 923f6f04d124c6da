#pragma once
// pmuctl's state verbs (interface.md section 3.2): watch, list, info, health, config get.
// Each returns the process exit status; messages a person can act on go to stderr
// ("no pmu-service on domain 0", "device 7 not seen on can0").

#include <chrono>
#include <cstdint>
#include <optional>
#include <string>

#include "pmu/dds/dds_context.hpp"
#include "pmuctl/call/global_options.hpp"
#include "pmuctl/verbs/verb.hpp"

namespace pmu::tools {

// The end of the call's wait: o.deadline, else --timeout or `default_timeout` s from now.
std::chrono::steady_clock::time_point wait_end(const GlobalOptions& o, double default_timeout);

// The partitions of pmuctl's participant for these options (pmu/dds_settings/vehicle.hpp).
pmu::dds::Partitions partitions_for(const GlobalOptions& o);
// "uav1/can0/1", or "can0/1" for the unnamed vehicle.
std::string device_label(const std::string& vehicle, const std::string& bus, std::uint16_t address);

int run_watch(const GlobalOptions& o, long count);
int run_list(const GlobalOptions& o);
int run_info(const GlobalOptions& o);
int run_health(const GlobalOptions& o);
int run_config_get(const GlobalOptions& o, const std::string& parameter);

// watch (--count, --low-rate into `g`), list, info, health: added to `app` in that order.
std::unique_ptr<Verb> add_state_verbs(CLI::App& app, GlobalOptions& g);
// config get [PARAM], added to the `config` subcommand.
std::unique_ptr<Verb> add_config_get(CLI::App& config);

}  // namespace pmu::tools
