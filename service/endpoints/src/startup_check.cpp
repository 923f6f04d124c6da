#include "pmu/endpoints/startup_check.hpp"

#include <cstdlib>

#include "pmu/dds/dds_context.hpp"
#include "pmu/dds/dds_qos_file.hpp"
#include "pmu/idl/topics.hpp"
#include "pmu/security/security_files.hpp"
#include "pmu/sysconf_dir.hpp"

namespace pmu::service {
namespace {

// The profiles DdsPublisher and DdsCommandEndpoint create the service's endpoints with.
const std::vector<dds::ProfileUse>& service_profiles() {
  static const std::vector<dds::ProfileUse> uses{
      {qos_profiles::kTelemetry, dds::EndpointKind::Writer, "the telemetry topics' writers"},
      {qos_profiles::kState, dds::EndpointKind::Writer, "the pmu/config, pmu/info and pmu/health writers"},
      {qos_profiles::kAlarms, dds::EndpointKind::Writer, "the pmu/alarms writer"},
      {qos_profiles::kCommand, dds::EndpointKind::Writer, "the pmu/command_reply writer"},
      {qos_profiles::kCommand, dds::EndpointKind::Reader, "the pmu/command reader"},
  };
  return uses;
}

// One of a hot-standby pair also writes and reads pmu/role and answers moves (DdsRoleEndpoint);
// a service alone needs none of these, so a QoS file made before them still starts it.
const std::vector<dds::ProfileUse>& pair_profiles() {
  static const std::vector<dds::ProfileUse> uses{
      {qos_profiles::kRole, dds::EndpointKind::Writer, "the pmu/role writer"},
      {qos_profiles::kRole, dds::EndpointKind::Reader, "the pmu/role reader"},
  };
  return uses;
}

void check_security(const Config& cfg, StartupCheck& out) {
  if (cfg.security.files.empty()) return;
  dds::SecurityCheckOptions options;
  options.warn_days = cfg.security.warn_days;
  options.domain = cfg.domain;
  for (const auto& i : dds::check_security_files(cfg.security.files, options)) {
    auto& list = i.level == dds::SecurityIssue::Level::Error ? out.errors : out.warnings;
    list.push_back(cfg.security.line_of(i.key) + ": " + i.message);
  }
}

// Which file the start will load, and where that choice was made, for messages: the config
// line of qos_file, $PMU_QOS_FILE, or the installed copy (dds::default_qos_file).
void check_qos(const Config& cfg, StartupCheck& out) {
  std::string where;
  if (!cfg.qos_file.empty()) {
    out.qos_file = cfg.qos_file;
    where = cfg.qos_file_line + ": qos_file: ";
  } else {
    out.qos_file = dds::default_qos_file();
    if (out.qos_file.empty()) {
      out.errors.push_back(cfg.source + ":1: no QoS profile file: no qos_file here, $PMU_QOS_FILE unset, and neither " +
                           PMU_SYSCONFDIR "/qos.xml nor " PMU_DATADIR
                                          "/qos.xml exists (install deploy/qos.xml, "
                                          "or set qos_file or PMU_QOS_FILE)");
      return;
    }
    if (const char* env = std::getenv("PMU_QOS_FILE"); env && *env) where = "$PMU_QOS_FILE: ";
  }
  auto uses = service_profiles();
  if (cfg.redundancy) uses.insert(uses.end(), pair_profiles().begin(), pair_profiles().end());
  for (const auto& p : dds::qos_file_problems(out.qos_file, uses)) out.errors.push_back(where + p);
}

// A `redundancy:` section makes this service one of a hot-standby pair on one shared CAN bus
// (docs/design.md, "Hot standby"): the CAN heartbeat that fences the pair runs on one bus, so a
// pair serves exactly one, and a real one: the built-in simulator is this process's own, which
// its peer cannot hear.
void check_redundancy(const Config& cfg, StartupCheck& out) {
  if (!cfg.redundancy) return;
  const auto& r = *cfg.redundancy;
  if (cfg.buses.size() != 1)
    out.errors.push_back(cfg.redundancy_line + ": redundancy: a hot-standby pair shares one CAN bus; this config has " +
                         std::to_string(cfg.buses.size()) + " buses");
  else if (cfg.buses.front().interface == "sim")
    out.errors.push_back(cfg.redundancy_line + ": redundancy: bus " + cfg.buses.front().name +
                         " is the built-in simulator (interface sim), which only this process hears: a pair needs a "
                         "CAN bus both hosts are on (socketcan:IFACE)");
  if (r.name == r.peer)
    out.errors.push_back(cfg.redundancy_line + ": redundancy: name " + r.name +
                         " is the peer's name too: each instance of a pair needs its own");
}

}  // namespace

// Fast DDS would only log a statistics writer the permissions refuse; DdsContext refuses to
// start with one (the same function decides). Needs permissions that passed check_security.
void check_statistics_grants(const Config& cfg, StartupCheck& out) {
  if (cfg.security.files.empty() || cfg.dds_statistics.empty() || !out.errors.empty()) return;
  if (const auto topic = dds::statistics_topic_not_granted(cfg.security.files, cfg.dds_statistics))
    out.errors.push_back(cfg.dds_statistics_line + ": dds_statistics: this identity's permissions (" +
                         cfg.security.files.permissions + ") do not allow publishing " + *topic +
                         " in the default partition (DDS-Security; docs/interface.md section 6 says what to grant)");
}

StartupCheck check_startup(const Config& cfg) {
  StartupCheck out;
  check_security(cfg, out);
  check_statistics_grants(cfg, out);
  check_qos(cfg, out);
  check_redundancy(cfg, out);
  return out;
}

}  // namespace pmu::service
