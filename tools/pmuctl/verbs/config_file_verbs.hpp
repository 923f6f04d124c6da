#pragma once
// pmuctl's configuration-file verbs (interface.md 3.2 and 4.6): a PMU's stored configuration
// as a file (snapshot), compared with the device (diff), and written to it safely (apply).
// The file format, its checks and the apply order are pmu::baseline's.

#include <string>

#include "pmuctl/verbs/state_verbs.hpp"
#include "pmuctl/verbs/verb.hpp"

namespace pmu::tools {

// Writes the chosen PMU's configuration to `file` ("-": stdout). An existing file is kept
// unless `force`; the file appears whole or not at all. Exit 0 written, 1 not writable,
// 2 bad usage or an existing file, 3 no answer.
int run_config_snapshot(const GlobalOptions& o, const std::string& file, bool force);

// The device against `file`, or against the baseline its service watches it with
// (pmu/baseline) when `file` is empty: exit 0 equal, 1 different (for the baseline also
// another unit than its serial pin), 2 a bad file (FILE:LINE) or no baseline, 3 nothing
// answers.
int run_config_diff(const GlobalOptions& o, const std::string& file);

// Validates the whole file first, then applies what differs in pmu::baseline's order, each
// change verified by the service's read-back; on a failure restores what it changed. Exit 0
// only when the final diff is clean; 1 a change failed (and what was restored), 2 a bad file
// or a change that needs --confirm, a file read from another serial without `other_unit`, or a
// can_address another served PMU has (nothing sent), 3 nothing answers. The dry run refuses
// what the apply would.
int run_config_apply(const GlobalOptions& o, const std::string& file, bool dry_run, bool confirm, bool other_unit);

// config snapshot, diff and apply, added to the `config` subcommand in that order; apply reads
// `confirm` (--confirm) when it runs.
std::unique_ptr<Verb> add_config_file_verbs(CLI::App& config, const bool& confirm);

}  // namespace pmu::tools
