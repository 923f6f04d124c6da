#pragma once
// `pmuctl serve [--listen ADDR] [--port N] [--client-queue KB] [--topic NAME]...`
// (docs/interface.md, "Live: Foxglove WebSocket"): the topics `record` would record, live,
// to Foxglove and Lichtblick over the Foxglove WebSocket protocol, until SIGINT or SIGTERM.
// The same channels and schemas as pmuctl's MCAP files; each sample's CDR bytes as received,
// its source timestamp as the message's time.

#include <string>
#include <vector>

#include "pmuctl/serve/serve_options.hpp"
#include "pmuctl/verbs/state_verbs.hpp"
#include "pmuctl/verbs/verb.hpp"

namespace pmu::tools {

// Exit status: 0 stopped by a signal; 1 the address cannot be listened on (in use, not this
// host's); 2 bad arguments (checked before, by the verb's Verb::check: --listen, --port,
// --client-queue, --allow-origin, --tls-cert and --tls-key).
int run_serve(const GlobalOptions& o, const ServeOptions& serve, const std::vector<std::string>& topics);

// serve; its listener, queue and access options are checked by Verb::check.
std::unique_ptr<Verb> add_serve_verb(CLI::App& app);

}  // namespace pmu::tools
