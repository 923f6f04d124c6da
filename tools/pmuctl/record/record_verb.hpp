#pragma once
// `pmuctl record FILE.mcap [--topic NAME]...` (docs/interface.md, "MCAP recordings"): every
// contract topic (or those named) into an MCAP file until SIGINT or SIGTERM, with each
// sample's CDR bytes as received and its source timestamp as log and publish time. A chunk
// reaches the file every second, so a crash loses at most the last second. A regular file is
// recorded as FILE.partial-XXXXXX beside FILE and renamed onto it when recording ends; a
// FIFO, a character device and "-" (standard output) are written in place (mcap_recording.hpp).

#include <string>
#include <vector>

#include "pmuctl/verbs/state_verbs.hpp"
#include "pmuctl/verbs/verb.hpp"

namespace pmu::tools {

// Exit status: 0 stopped by a signal and the file closed; 1 the file could not be written
// (disk full, a reader that went away: what and where on stderr); 2 bad arguments, or a path
// that cannot be created or is refused (a directory, ...), before any DDS participant exists.
int run_record(const GlobalOptions& o, const std::string& path, const std::vector<std::string>& topics);

std::unique_ptr<Verb> add_record_verb(CLI::App& app);

}  // namespace pmu::tools
