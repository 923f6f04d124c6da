#pragma once
// pmuctl alarms (interface.md section 3.2): the alarms of every service on the domain that are
// not NORMAL, from pmu/alarms (TRANSIENT_LOCAL: each service's current set arrives at once).

#include "pmuctl/verbs/state_verbs.hpp"
#include "pmuctl/verbs/verb.hpp"

namespace pmu::tools {

int run_alarms(const GlobalOptions& o);

// alarms, and alarms ack CODE [--kind KIND] (run_alarm_ack, command_verbs.hpp), added to `app`.
std::unique_ptr<Verb> add_alarm_verbs(CLI::App& app);

}  // namespace pmu::tools
