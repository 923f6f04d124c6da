#pragma once
// How pmuctl energy prints one device's figures (interface.md section 3.2): with --json one
// line per device, else a block of lines headed by the device's label. NaN (not known) is
// `null` in JSON and `-` in text.

#include "pmu/idl/energy.h"
#include "pmuctl/verbs/state_verbs.hpp"

namespace pmu::tools {

// A PMU's pmu/energy: the outputs', generator's and batteries' figures.
void print_energy(const GlobalOptions& o, const pmu::v5::Energy& e);
// A BMS-reported battery's pmu/bms_energy, labelled as watch labels it (`can0/battery2`).
void print_bms_energy(const GlobalOptions& o, const pmu::v5::BmsEnergy& e);

}  // namespace pmu::tools
