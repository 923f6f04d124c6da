#include "pmu/app/logging.hpp"

#include <spdlog/cfg/env.h>
#include <spdlog/sinks/dup_filter_sink.h>
#include <spdlog/sinks/stdout_color_sinks.h>
#include <spdlog/sinks/systemd_sink.h>
#include <spdlog/spdlog.h>

#include <chrono>
#include <cstdlib>

namespace pmu::service {

std::string choose_log_level(const std::string& option, const std::string& config_level) {
  if (!option.empty()) return option;
  if (const char* env = std::getenv("PMU_LOG_LEVEL"); env && *env) return env;
  return config_level.empty() ? "info" : config_level;
}

bool setup_logging(const std::string& level) {
  auto dedup = std::make_shared<spdlog::sinks::dup_filter_sink_mt>(std::chrono::seconds(5));
  const bool journal = std::getenv("JOURNAL_STREAM") != nullptr;
  if (journal) {
    dedup->add_sink(std::make_shared<spdlog::sinks::systemd_sink_mt>("pmu-service"));
  } else {
    dedup->add_sink(std::make_shared<spdlog::sinks::stderr_color_sink_mt>());
  }
  auto logger = std::make_shared<spdlog::logger>("pmu", dedup);
  // The journal stamps its own time and unit; the console needs both.
  logger->set_pattern(journal ? "%v" : "%Y-%m-%d %H:%M:%S.%e %^%-5l%$ %v");
  spdlog::set_default_logger(logger);
  const auto lvl = spdlog::level::from_str(level);
  if (lvl == spdlog::level::off && level != "off") {
    spdlog::error("log level '{}' is not one of trace, debug, info, warn, error, critical, off", level);
    return false;
  }
  spdlog::set_level(lvl);
  spdlog::cfg::load_env_levels();
  return true;
}

}  // namespace pmu::service
