#pragma once
// pmuctl preflight (interface.md section 3.2): whether each vehicle may fly, from
// pmu/readiness. Exit status 0 when every vehicle read is ready, 1 when one is not (its
// reasons printed), 3 when no service answers.

#include "pmuctl/verbs/state_verbs.hpp"
#include "pmuctl/verbs/verb.hpp"

namespace pmu::tools {

int run_preflight(const GlobalOptions& o);

std::unique_ptr<Verb> add_preflight_verb(CLI::App& app);

}  // namespace pmu::tools
