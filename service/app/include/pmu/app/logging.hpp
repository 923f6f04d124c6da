#pragma once
// Logging set-up for pmu-service: spdlog to the journal under systemd (JOURNAL_STREAM set by
// systemd for our stderr) and to the console otherwise. Identical messages within 5 s are
// collapsed ("Skipped N duplicate messages..."), so a bus error flood cannot fill the journal.
// Level: --log-level, else $PMU_LOG_LEVEL, else the config's log_level; $SPDLOG_LEVEL may
// then set per-logger levels (spdlog::cfg::load_env_levels).

#include <string>

namespace pmu::service {

// Returns false (and logs why) when `level` is not a spdlog level name.
bool setup_logging(const std::string& level);
// The level chosen from the option, the environment and the config, as described above.
std::string choose_log_level(const std::string& option, const std::string& config_level);

}  // namespace pmu::service
