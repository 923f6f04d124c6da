#pragma once
// pmuctl alarms (interface.md section 3.2): the alarms of every service on the domain that are
// not NORMAL, from pmu/alarms (TRANSIENT_LOCAL: each service's current set arrives at once).

#include "pmuctl/verbs/state_verbs.hpp"

namespace pmu::tools {

int run_alarms(const GlobalOptions& o);

}  // namespace pmu::tools
