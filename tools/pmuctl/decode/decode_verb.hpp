#pragma once
// pmuctl decode [FILE] [--firmware X.Y] [--mcap OUT] (interface.md section 3.2): a candump log
// decoded offline, printed as text or JSON lines, or written as an MCAP file (mcap_decode.hpp).
// It needs no DDS and no target: it runs whole while run_cli types the verbs' values
// (Verb::take_values), before the target, identity and network options are checked.

#include "pmuctl/verbs/verb.hpp"

namespace pmu::tools {

std::unique_ptr<Verb> add_decode_verb(CLI::App& app);

}  // namespace pmu::tools
