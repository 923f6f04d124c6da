#pragma once
// pmuctl energy (interface.md section 3.2): each PMU's power per output, generator power,
// energy out of each battery and endurance, from pmu/energy, then each BMS-reported
// battery's power, energy used and endurance, from pmu/bms_energy (both TRANSIENT_LOCAL: the
// latest figures of each device arrive at once). Exit 0 with figures, 2 when no selected
// device has any, 3 when no service answers.

#include "pmuctl/verbs/state_verbs.hpp"
#include "pmuctl/verbs/verb.hpp"

namespace pmu::tools {

int run_energy(const GlobalOptions& o);

std::unique_ptr<Verb> add_energy_verb(CLI::App& app);

}  // namespace pmu::tools
