// pmu-mavlink: the power system on the aircraft's MAVLink network (interface.md
// "pmu-mavlink"). A DDS client of pmu-service like any ground station (same vehicle,
// partitions and DDS-Security identity; it never touches the bus) and a MAVLink 2 component
// with its own id: HEARTBEAT, BATTERY_STATUS, GENERATOR_STATUS and RELAY_STATUS at their
// rates, alarms and readiness as STATUSTEXT, SET_MESSAGE_INTERVAL and RUN_PREARM_CHECKS
// answered, the PMUs' settings as parameters and COMMAND_LONG as the service's commands (its
// one DDS writer).
#include <CLI/CLI.hpp>
#include <poll.h>

#include <chrono>
#include <csignal>
#include <cstdio>
#include <memory>
#include <vector>

#include "link/serial_endpoint.hpp"
#include "link/udp_endpoint.hpp"
#include "pmu/dds_settings/vehicle.hpp"
#include "pmu/dds/command_sample.hpp"
#include "pmu/dds/dds_context.hpp"
#include "pmu/files/bounded_file.hpp"
#include "pmu/security/security_files.hpp"
#include "program/bridge.hpp"
#include "program/dds_inputs.hpp"
#include "program/operations.hpp"
#include "program/service_link.hpp"
#include "program/settings.hpp"
#include "signing/signing_key_file.hpp"

namespace {

volatile std::sig_atomic_t g_stop = 0;
void on_signal(int) { g_stop = 1; }

}  // namespace

int main(int argc, char** argv) {
  using namespace pmu::mavlink_bridge;
  CLI::App app{"pmu-mavlink: pmu-service's power system as a MAVLink 2 component"};
  std::string config_file, udp_text, serial_text, vehicle_text;
  std::optional<int> system_id, component_id, domain, pmu_id, bms_id;
  std::optional<std::string> vehicle, qos_file, security_dir, identity, signing_key;
  std::vector<std::string> rates, confirms;
  app.add_option("--config", config_file, "YAML file with any of the settings below (the options win)");
  app.add_option("--udp", udp_text, "UDP client endpoint HOST:PORT (sends there, takes what comes back)");
  app.add_option("--serial", serial_text, "serial endpoint DEVICE:BAUD (the autopilot's TELEM port)");
  app.add_option("--system-id", system_id, "MAVLink system id (default: the autopilot's, from its HEARTBEAT)")
      ->check(CLI::Range(1, 255));
  app.add_option("--component-id", component_id, "MAVLink component id (default 180, MAV_COMP_ID_BATTERY)")
      ->check(CLI::Range(1, 255));
  app.add_option("--domain", domain, "DDS domain of pmu-service (default 0)")->check(CLI::Range(0, 232));
  app.add_option("--vehicle", vehicle, "the vehicle whose service to read (default: the unnamed vehicle)");
  app.add_option("--qos-file", qos_file, "QoS profiles (default: $PMU_QOS_FILE, then the installed qos.xml)");
  app.add_option("--security-dir", security_dir, "DDS-Security folder (deploy/security/make_pki.sh)");
  app.add_option("--identity", identity, "DDS-Security identity in that folder");
  app.add_option("--signing-key", signing_key,
                 "MAVLink 2 signing: file holding the passphrase the ground stations use (one line, chmod 600)");
  app.add_option("--battery-id-pmu", pmu_id, "BATTERY_STATUS id of the first PMU's battery A (default 10)")
      ->check(CLI::Range(0, 253));
  app.add_option("--battery-id-bms", bms_id, "BATTERY_STATUS id of the first BMS (default 20)")
      ->check(CLI::Range(0, 254));
  app.add_option("--rate", rates, "NAME=HZ: heartbeat, battery_status, generator_status, relay_status (0: off)");
  app.add_option("--confirm", confirms,
                 "RULE: commands and parameter sets under this confirm rule go to the service confirmed "
                 "(repeatable; added to the config's confirm: list)");
  CLI11_PARSE(app, argc, argv);

  Settings settings;
  try {
    if (!config_file.empty()) {
      const auto file = pmu::files::read_bounded_file(config_file, 1 << 20);
      if (!file.ok()) throw SettingsError(config_file + " cannot be read: " + file.error);
      read_settings(file.text, config_file, settings);
    }
  } catch (const SettingsError& e) {
    std::fprintf(stderr, "pmu-mavlink: %s\n", e.what());
    return 2;
  }
  auto fail = [](const std::string& what) {
    std::fprintf(stderr, "pmu-mavlink: %s\n", what.c_str());
    return 2;
  };
  if (!udp_text.empty()) {
    auto r = parse_udp_address(udp_text);
    if (auto* e = std::get_if<std::string>(&r)) return fail("--udp " + *e);
    settings.udp = std::get<UdpAddress>(r);
  }
  if (!serial_text.empty()) {
    auto r = parse_serial_address(serial_text);
    if (auto* e = std::get_if<std::string>(&r)) return fail("--serial " + *e);
    settings.serial = std::get<SerialAddress>(r);
  }
  if (system_id) settings.system_id = static_cast<std::uint8_t>(*system_id);
  if (component_id) settings.component_id = static_cast<std::uint8_t>(*component_id);
  if (domain) settings.domain = *domain;
  if (vehicle) settings.vehicle = *vehicle;
  if (qos_file) settings.qos_file = *qos_file;
  if (security_dir) settings.security_dir = *security_dir;
  if (identity) settings.identity = *identity;
  if (signing_key) settings.signing_key = *signing_key;
  if (pmu_id) settings.pmu_battery_id = static_cast<std::uint8_t>(*pmu_id);
  if (bms_id) settings.bms_battery_id = static_cast<std::uint8_t>(*bms_id);
  for (const auto& r : rates)
    if (auto e = apply_rate_option(r, settings)) return fail(*e);
  for (const auto& r : confirms)
    if (auto e = apply_confirm_option(r, settings)) return fail(*e);
  if (!settings.udp && !settings.serial) return fail("no endpoint: give --udp HOST:PORT or --serial DEVICE:BAUD");
  if (settings.security_dir.empty() != settings.identity.empty())
    return fail("--security-dir and --identity go together");

  pmu::dds::SecurityFiles security;
  if (!settings.security_dir.empty()) {
    security = pmu::dds::security_files_in(settings.security_dir, settings.identity);
    pmu::dds::SecurityCheckOptions options;
    options.domain = settings.domain;
    const auto issues = pmu::dds::check_security_files(security, options);
    for (const auto& i : issues)
      std::fprintf(stderr, "pmu-mavlink: %s%s\n",
                   i.level == pmu::dds::SecurityIssue::Level::Error ? "" : "warning: ", i.message.c_str());
    if (pmu::dds::has_errors(issues)) return 2;
  }

  // Checked before any endpoint or participant opens, like the DDS-Security files.
  std::optional<Bridge::Signing> signing;
  if (!settings.signing_key.empty()) {
    const auto key_file = read_signing_key_file(settings.signing_key);
    for (const auto& i : key_file.issues)
      std::fprintf(stderr, "pmu-mavlink: %s%s\n", i.error ? "" : "warning: ", i.message.c_str());
    if (!key_file.key) return 2;
    signing = Bridge::Signing{*key_file.key, [] {
                                const auto since_epoch = std::chrono::system_clock::now().time_since_epoch();
                                const auto us = std::chrono::duration_cast<std::chrono::microseconds>(since_epoch);
                                return pmu::mavlink::signing_timestamp(static_cast<std::uint64_t>(us.count()));
                              }};
  }

  std::vector<std::unique_ptr<Endpoint>> endpoints;
  try {
    if (settings.udp) endpoints.push_back(std::make_unique<UdpEndpoint>(*settings.udp));
    if (settings.serial) endpoints.push_back(std::make_unique<SerialEndpoint>(*settings.serial));
  } catch (const LinkError& e) {
    return fail(e.what());
  }

  std::unique_ptr<pmu::dds::DdsContext> dds;
  std::unique_ptr<DdsInputs> inputs;
  std::unique_ptr<ServiceLink> link;
  try {
    const auto partitions = pmu::dds::vehicle_partitions(settings.vehicle);
    const std::string qos = settings.qos_file.empty() ? pmu::dds::default_qos_file() : settings.qos_file;
    // The default transport and network (as pmu-service's defaults), in the vehicle's partitions.
    dds = std::make_unique<pmu::dds::DdsContext>(settings.domain, qos, "pmu-mavlink", security,
                                                 pmu::dds::Transport::Default, pmu::dds::ResolvedNetwork{},
                                                 pmu::dds::Partitions{partitions, partitions});
    inputs = std::make_unique<DdsInputs>(*dds);
    link = std::make_unique<ServiceLink>(*dds, settings.vehicle);
  } catch (const std::exception& e) {
    return fail(e.what());
  }

  std::vector<Endpoint*> raw;
  for (auto& e : endpoints) raw.push_back(e.get());
  Bridge bridge(settings, raw, *inputs, signing);
  // Request ids "pmu-mavlink-HOST-PID-N", N from the start's ns: at most 57 bytes (the
  // contract allows 63) and never one a restart with the same pid used.
  const auto start_ns = static_cast<std::uint64_t>(
      std::chrono::duration_cast<std::chrono::nanoseconds>(std::chrono::system_clock::now().time_since_epoch()).count());
  Operations operations(settings, bridge, *inputs, *link, pmu::dds::request_id_prefix("pmu-mavlink", 16), start_ns);
  bridge.set_frame_handler([&operations](const pmu::mavlink::Frame& frame, const Bridge::Send& send,
                                         Bridge::Clock::time_point now) { operations.on_frame(frame, send, now); });

  struct sigaction sa {};
  sa.sa_handler = on_signal;
  ::sigaction(SIGINT, &sa, nullptr);
  ::sigaction(SIGTERM, &sa, nullptr);
  std::signal(SIGPIPE, SIG_IGN);

  for (const auto& e : endpoints)
    std::fprintf(stderr, "pmu-mavlink: %s, component %u\n", e->describe().c_str(),
                 static_cast<unsigned>(settings.component_id));
  if (signing) {
    std::fprintf(stderr,
                 "pmu-mavlink: MAVLink signing on (%s): frames out signed; commands and parameter messages "
                 "addressed to this component taken only signed with that key\n",
                 settings.signing_key.c_str());
  } else {
    std::fprintf(stderr,
                 "pmu-mavlink: MAVLink signing off (no --signing-key): any sender that reaches an endpoint, anyone in "
                 "range of a radio link among them, can command the power system\n");
  }
  int status = 0;
  std::vector<pollfd> fds;
  for (const auto& e : endpoints) fds.push_back({e->fd(), POLLIN, 0});
  while (!g_stop) {
    // 20 ms: DDS samples are taken on this loop, so this bounds how late an alarm is said.
    ::poll(fds.data(), fds.size(), 20);
    const auto now = Bridge::Clock::now();
    if (!bridge.step(now)) {
      std::fprintf(stderr, "pmu-mavlink: an endpoint is gone\n");
      status = 1;
      break;
    }
    operations.step(now);
  }
  const auto& p = bridge.parser_counters();
  std::fprintf(stderr,
               "pmu-mavlink: frames in %llu (bad CRC %llu, unknown id %llu, MAVLink 1 %llu, bad flags %llu, "
               "garbage bytes %llu), frames out %llu\n",
               static_cast<unsigned long long>(p.frames), static_cast<unsigned long long>(p.bad_crc),
               static_cast<unsigned long long>(p.unknown_message), static_cast<unsigned long long>(p.mavlink1_frames),
               static_cast<unsigned long long>(p.unsupported_incompat_flags),
               static_cast<unsigned long long>(p.garbage_bytes), static_cast<unsigned long long>(bridge.frames_sent()));
  if (const auto* c = bridge.signing_counters()) {
    std::fprintf(stderr,
                 "pmu-mavlink: signing: frames signed %llu, accepted %llu; refused: unsigned %llu, bad signature %llu, "
                 "replayed %llu, stale %llu, too many streams %llu\n",
                 static_cast<unsigned long long>(c->signed_out), static_cast<unsigned long long>(c->accepted),
                 static_cast<unsigned long long>(c->unsigned_frames), static_cast<unsigned long long>(c->bad_signature),
                 static_cast<unsigned long long>(c->replayed), static_cast<unsigned long long>(c->stale),
                 static_cast<unsigned long long>(c->too_many_streams));
  }
  for (const auto& line : operations.report()) std::fprintf(stderr, "pmu-mavlink: %s\n", line.c_str());
  for (const auto& e : endpoints) {
    const auto& c = e->counters();
    std::fprintf(stderr, "pmu-mavlink: %s: bytes in %llu, out %llu, send failures %llu, read failures %llu\n",
                 e->describe().c_str(), static_cast<unsigned long long>(c.bytes_in),
                 static_cast<unsigned long long>(c.bytes_out), static_cast<unsigned long long>(c.send_failures),
                 static_cast<unsigned long long>(c.read_failures));
  }
  return status;
}
