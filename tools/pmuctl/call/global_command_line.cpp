#include "pmuctl/call/global_command_line.hpp"

#include <CLI/CLI.hpp>
#include <cstdio>
#include <cstdlib>
#include <variant>

#include "pmu/codec/ids.hpp"
#include "pmu/command/command.hpp"
#include "pmu/dds_settings/vehicle.hpp"
#include "pmu/sysconf_dir.hpp"
#include "pmuctl/call/exit_status.hpp"
#include "pmuctl/call/option_values.hpp"

namespace pmu::tools {
namespace {

std::string env_or(const char* name, const std::string& fallback) {
  const char* v = std::getenv(name);
  return v && *v ? std::string(v) : fallback;
}

// --security-dir/--identity (or PMU_SECURITY_DIR/PMU_SECURITY_IDENTITY) into the six files,
// checked before anything touches DDS. False (after printing why) when they are unusable.
bool setup_security(GlobalOptions& g, std::string dir, std::string identity) {
  dir = dir.empty() ? env_or("PMU_SECURITY_DIR", "") : dir;
  identity = identity.empty() ? env_or("PMU_SECURITY_IDENTITY", "") : identity;
  if (dir.empty()) {
    if (!identity.empty()) {
      std::fprintf(stderr, "pmuctl: --identity %s needs --security-dir DIR (or PMU_SECURITY_DIR)\n", identity.c_str());
      return false;
    }
    return true;
  }
  if (identity.empty()) {
    std::fprintf(stderr,
                 "pmuctl: --security-dir %s needs --identity NAME (or PMU_SECURITY_IDENTITY), "
                 "e.g. ground-station to command, mission-computer to watch\n",
                 dir.c_str());
    return false;
  }
  g.security = pmu::dds::security_files_in(dir, identity);
  pmu::dds::SecurityCheckOptions options;
  options.domain = g.domain;
  const auto issues = pmu::dds::check_security_files(g.security, options);
  for (const auto& i : issues)
    std::fprintf(stderr, "pmuctl: %s%s\n",
                 i.level == pmu::dds::SecurityIssue::Level::Error ? "" : "warning: ", i.message.c_str());
  return !pmu::dds::has_errors(issues);
}

// --vehicle (or PMU_VEHICLE) checked like the service's config key. An option given as ""
// names the unnamed vehicle; absent, readers see every vehicle.
bool setup_vehicle(GlobalOptions& g, const CLI::Option* option, const std::string& value) {
  const char* from = "--vehicle";
  if (option->count() > 0) {
    g.vehicle = value;
  } else if (const char* env = std::getenv("PMU_VEHICLE")) {
    g.vehicle = std::string(env);
    from = "PMU_VEHICLE";
  }
  if (!g.vehicle) return true;
  if (const auto why = pmu::dds::vehicle_name_problem(*g.vehicle); !why.empty()) {
    std::fprintf(stderr, "pmuctl: %s '%s' %s\n", from, pmu::service::printable(*g.vehicle).c_str(), why.c_str());
    return false;
  }
  return true;
}

}  // namespace

void add_global_options(CLI::App& app, GlobalOptions& g, GlobalOptionText& text) {
  app.add_option("--domain", g.domain, "DDS domain id")->check(CLI::Range(0, 232));
  text.vehicle_option = app.add_option(
      "--vehicle", text.vehicle,
      "Only this vehicle (config `vehicle` of its service); commands go to it (default: $PMU_VEHICLE; none: "
      "read every vehicle, command the unnamed one)");
  app.add_option("--bus", g.bus, "Only this bus (the service's name for it, e.g. can0)");
  app.add_option("--address", text.address,
                 "Only the PMU at this CAN address (0..65534); 65535 (broadcast) with `engine stop` alone: to every "
                 "PMU of the bus (--bus) or of the vehicle")
      ->check(CLI::Range(0, int{pmu::codec::kBroadcastAddress}));
  app.add_flag("--json", g.json, "Machine-readable output: one JSON object per line");
  app.add_option("--timeout", text.timeout, "Seconds to wait (state verbs: default 3; commands: 5; watch: forever)")
      ->type_name("S");
  app.add_option("--qos-file", g.qos_file,
                 "QoS profiles (default: $PMU_QOS_FILE, else " PMU_SYSCONFDIR "/qos.xml, else " PMU_DATADIR
                 "/qos.xml)");
  app.add_option("--security-dir", text.security_dir,
                 "DDS-Security: the folder deploy/security/make_pki.sh made (default: $PMU_SECURITY_DIR; "
                 "none: no security)");
  app.add_option("--identity", text.identity,
                 "DDS-Security identity in that folder: ground-station (commands) or mission-computer "
                 "(read-only) (default: $PMU_SECURITY_IDENTITY)");
  app.add_option("--peer", text.network.peers,
                 "Unicast discovery (multicast off): ADDR[:PORT] of a host to discover, an IPv4 address or host "
                 "name; repeat for more (default: $PMU_DDS_PEERS, comma separated)")
      ->allow_extra_args(false);
  app.add_option("--discovery-server", text.network.discovery_servers,
                 "Client of Fast DDS Discovery Server(s) ADDR[:PORT][,ADDR[:PORT]...] (port 11811 if none; "
                 "server id = position, as `fastdds discovery -i ID`) (default: $PMU_DISCOVERY_SERVER)");
  app.add_option("--interface", text.network.interfaces,
                 "DDS over UDP only on this interface (name or IPv4 address); repeat for more "
                 "(default: $PMU_DDS_INTERFACES, comma separated; none: every interface)")
      ->allow_extra_args(false);
  app.add_option("--link", text.network.link,
                 "The link to the aircraft: radio (announcements, leases and heartbeats for a radio's round trip; "
                 "watch reads the low-rate topics) or none (default: $PMU_LINK, else none)")
      ->type_name("PROFILE");
  app.add_flag("--no-agent", g.no_agent, "Run this call on its own, not through a `pmuctl agent` of this host");
  app.add_flag("--confirm", text.confirm,
               "Confirm a command the safety policy guards (avionics off, reset, engine start...)");
}

std::optional<int> take_target_and_wait(GlobalOptions& g, const GlobalOptionText& text) {
  if (text.address >= 0) g.address = static_cast<std::uint16_t>(text.address);
  if (!text.timeout.empty()) {
    const auto t = parse_seconds("--timeout", text.timeout);
    if (const auto* why = std::get_if<std::string>(&t)) return fail(g, ExitStatus::BadUsage, *why);
    g.timeout = std::get<double>(t);
  }
  return std::nullopt;
}

bool resolve_identity_and_network(GlobalOptions& g, const GlobalOptionText& text) {
  if (!setup_security(g, text.security_dir, text.identity)) return false;
  if (!setup_vehicle(g, text.vehicle_option, text.vehicle)) return false;
  return resolve_network_options(text.network, pmu::dds::system_lookup(), !g.security.empty(), g.network);
}

}  // namespace pmu::tools
