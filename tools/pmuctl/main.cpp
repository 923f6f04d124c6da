// pmuctl: the operator's command line (interface.md section 3.2): the DDS verbs that read
// what pmu-service publishes, and the offline decoder for candump logs.

#include <sys/types.h>

#include <CLI/CLI.hpp>
#include <algorithm>
#include <cctype>
#include <chrono>
#include <cstdint>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <memory>
#include <optional>
#include <string>

#include "pmu/codec/firmware.hpp"
#include "pmu/codec/messages.hpp"
#include "pmu/codec/parameters.hpp"
#include "pmu/idl/command.h"
#include "pmuctl/decode/log_decoder.hpp"
#include "pmuctl/record/mcap_decode.hpp"
#include "pmuctl/record/record_verb.hpp"
#include "pmuctl/serve/serve_verb.hpp"
#include "pmuctl/verbs/command_verbs.hpp"
#include "pmuctl/verbs/config_file_verbs.hpp"
#include "pmuctl/verbs/alarm_verbs.hpp"
#include "pmuctl/verbs/energy_verb.hpp"
#include "pmuctl/verbs/preflight_verb.hpp"
#include "pmuctl/verbs/state_verbs.hpp"
#include "pmuctl/view/mask_names.hpp"
#include "pmu/command/command.hpp"
#include "pmu/config/vehicle.hpp"
#include "pmuctl/call/network_options.hpp"
#include "pmu/sysconf_dir.hpp"
#include "pmu/version.hpp"
#include "pmuctl/call/exit_status.hpp"
#include "pmuctl/call/option_values.hpp"
#include "pmuctl/agent/agent_client.hpp"
#include "pmuctl/agent/agent_request.hpp"
#include "pmuctl/agent/agent_server.hpp"
#include "pmuctl/call/context_lease.hpp"

namespace {

struct FileCloser {
  void operator()(std::FILE* f) const {
    if (f && f != stdin) std::fclose(f);
  }
};

int run_decode(const std::string& path, const pmu::tools::DecodeOptions& options) {
  std::unique_ptr<std::FILE, FileCloser> in(path == "-" ? stdin : std::fopen(path.c_str(), "r"));
  if (!in) {
    std::fprintf(stderr, "pmuctl decode: cannot open %s: %s\n", path.c_str(), std::strerror(errno));
    return 2;
  }
  pmu::tools::LogDecoder decoder(options);
  std::string out = decoder.header();
  out.reserve(1 << 17);
  char* line = nullptr;
  std::size_t cap = 0;
  ssize_t len = 0;
  while ((len = ::getline(&line, &cap, in.get())) >= 0) {
    std::size_t n = static_cast<std::size_t>(len);
    while (n > 0 && (line[n - 1] == '\n' || line[n - 1] == '\r')) --n;
    decoder.decode_line(std::string_view(line, n), out);
    if (out.size() >= (1 << 16)) {
      std::fwrite(out.data(), 1, out.size(), stdout);
      out.clear();
    }
  }
  const bool read_error = std::ferror(in.get()) != 0;
  std::free(line);
  std::fwrite(out.data(), 1, out.size(), stdout);
  std::fflush(stdout);
  if (read_error) {
    std::fprintf(stderr, "pmuctl decode: error reading %s\n", path.c_str());
    return 2;
  }
  const auto& c = decoder.counts();
  if (c.relative_times > 0)
    std::fprintf(stderr,
                 "pmuctl decode: %llu lines have times before 1973, as candump -td (deltas) or -tz (since its "
                 "start) writes them: printed as given, not as dates (candump -L or -ta logs absolute times)\n",
                 static_cast<unsigned long long>(c.relative_times));
  std::fprintf(stderr, "pmuctl decode: %llu lines, %llu frames decoded, %llu errors\n",
               static_cast<unsigned long long>(c.lines), static_cast<unsigned long long>(c.frames),
               static_cast<unsigned long long>(c.errors));
  return 0;
}

std::string env_or(const char* name, const std::string& fallback) {
  const char* v = std::getenv(name);
  return v && *v ? std::string(v) : fallback;
}

// --security-dir/--identity (or PMU_SECURITY_DIR/PMU_SECURITY_IDENTITY) into the six files,
// checked before anything touches DDS. False (after printing why) when they are unusable.
bool setup_security(pmu::tools::GlobalOptions& g, std::string dir, std::string identity) {
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
    std::fprintf(stderr, "pmuctl: --security-dir %s needs --identity NAME (or PMU_SECURITY_IDENTITY), "
                         "e.g. ground-station to command, mission-computer to watch\n", dir.c_str());
    return false;
  }
  g.security = pmu::dds::security_files_in(dir, identity);
  pmu::dds::SecurityCheckOptions options;
  options.domain = g.domain;
  const auto issues = pmu::dds::check_security_files(g.security, options);
  for (const auto& i : issues)
    std::fprintf(stderr, "pmuctl: %s%s\n", i.level == pmu::dds::SecurityIssue::Level::Error ? "" : "warning: ",
                 i.message.c_str());
  return !pmu::dds::has_errors(issues);
}

// --vehicle (or PMU_VEHICLE) checked like the service's config key. An option given as ""
// names the unnamed vehicle; absent, readers see every vehicle.
bool setup_vehicle(pmu::tools::GlobalOptions& g, const CLI::Option* option, const std::string& value) {
  const char* from = "--vehicle";
  if (option->count() > 0) {
    g.vehicle = value;
  } else if (const char* env = std::getenv("PMU_VEHICLE")) {
    g.vehicle = std::string(env);
    from = "PMU_VEHICLE";
  }
  if (!g.vehicle) return true;
  if (const auto why = pmu::service::vehicle_name_problem(*g.vehicle); !why.empty()) {
    std::fprintf(stderr, "pmuctl: %s '%s' %s\n", from, pmu::service::printable(*g.vehicle).c_str(), why.c_str());
    return false;
  }
  return true;
}

// Set when `pmuctl agent` runs a call: its participants, its DDS settings, the call's
// request (its caller's deadline and lane), and why it declined the call (left empty when it
// ran it).
struct AgentCall {
  pmu::tools::ContextPool& pool;
  const pmu::tools::GlobalOptions& settings;
  const pmu::tools::AgentRequest& request;
  std::string& declined;
};

std::uint64_t epoch_ns_now() {
  return static_cast<std::uint64_t>(std::chrono::duration_cast<std::chrono::nanoseconds>(
                                        std::chrono::system_clock::now().time_since_epoch())
                                        .count());
}

int run_cli(int argc, char** argv, const AgentCall* served) {
  // The moment the call was made: its caller's wait is counted from here, also through the
  // agent, however long the call waits there (docs/safety.md H9).
  const auto began = std::chrono::steady_clock::now();
  const std::uint64_t began_ns = epoch_ns_now();
  CLI::App app{"pmuctl: operate and inspect Millswood 250W PMUs served by pmu-service"};
  app.require_subcommand(1);
  app.fallthrough();  // global options may follow the verb: `pmuctl decode --json`
  app.set_version_flag("--version", "pmuctl " PMU_VERSION_TEXT);
  pmu::tools::GlobalOptions g;
  int address = -1;
  std::string timeout;
  app.add_option("--domain", g.domain, "DDS domain id")->check(CLI::Range(0, 232));
  std::string vehicle;
  auto* vehicle_option = app.add_option(
      "--vehicle", vehicle,
      "Only this vehicle (config `vehicle` of its service); commands go to it (default: $PMU_VEHICLE; none: "
      "read every vehicle, command the unnamed one)");
  app.add_option("--bus", g.bus, "Only this bus (the service's name for it, e.g. can0)");
  app.add_option("--address", address,
                 "Only the PMU at this CAN address (0..65534); 65535 (broadcast) with `engine stop` alone: to every "
                 "PMU of the bus (--bus) or of the vehicle")
      ->check(CLI::Range(0, int{pmu::codec::kBroadcastAddress}));
  app.add_flag("--json", g.json, "Machine-readable output: one JSON object per line");
  app.add_option("--timeout", timeout, "Seconds to wait (state verbs: default 3; commands: 5; watch: forever)")
      ->type_name("S");
  app.add_option("--qos-file", g.qos_file, "QoS profiles (default: $PMU_QOS_FILE, else " PMU_SYSCONFDIR "/qos.xml, else " PMU_DATADIR "/qos.xml)");
  std::string security_dir, identity;
  app.add_option("--security-dir", security_dir,
                 "DDS-Security: the folder deploy/security/make_pki.sh made (default: $PMU_SECURITY_DIR; "
                 "none: no security)");
  app.add_option("--identity", identity,
                 "DDS-Security identity in that folder: ground-station (commands) or mission-computer "
                 "(read-only) (default: $PMU_SECURITY_IDENTITY)");
  pmu::tools::NetworkOptions network;
  app.add_option("--peer", network.peers,
                 "Unicast discovery (multicast off): ADDR[:PORT] of a host to discover, an IPv4 address or host "
                 "name; repeat for more (default: $PMU_DDS_PEERS, comma separated)")
      ->allow_extra_args(false);
  app.add_option("--discovery-server", network.discovery_servers,
                 "Client of Fast DDS Discovery Server(s) ADDR[:PORT][,ADDR[:PORT]...] (port 11811 if none; "
                 "server id = position, as `fastdds discovery -i ID`) (default: $PMU_DISCOVERY_SERVER)");
  app.add_option("--interface", network.interfaces,
                 "DDS over UDP only on this interface (name or IPv4 address); repeat for more "
                 "(default: $PMU_DDS_INTERFACES, comma separated; none: every interface)")
      ->allow_extra_args(false);
  app.add_option("--link", network.link,
                 "The link to the aircraft: radio (announcements, leases and heartbeats for a radio's round trip; "
                 "watch reads the low-rate topics) or none (default: $PMU_LINK, else none)")
      ->type_name("PROFILE");
  app.add_flag("--no-agent", g.no_agent, "Run this call on its own, not through a `pmuctl agent` of this host");

  auto* agent = app.add_subcommand(
      "agent", "Keep this host's DDS participants for the pmuctl calls made on it (a ground station on a radio "
               "link) until Ctrl-C or SIGTERM");
  std::string agent_socket;
  agent->add_option("--socket", agent_socket,
                    "The socket calls find it at (default: $PMU_AGENT_SOCKET, else $XDG_RUNTIME_DIR/pmu-dds/"
                    "agent-DOMAIN.sock, else /run/pmu-dds/agent-DOMAIN.sock)")
      ->type_name("PATH");
  int agent_workers = 4;
  auto* workers_option = agent->add_option("--workers", agent_workers,
                    "Calls served at once, each by a process with its own DDS participant (default 4; 1 with --link "
                    "radio), besides one "
                    "for engine stops, which never wait. Calls go to the first while it keeps up; the next takes "
                    "one when all before it have been on theirs for 5 s, so a call that waits for a silent "
                    "aircraft holds up no other for longer")
      ->check(CLI::Range(1, 16));

  auto* watch = app.add_subcommand("watch", "Live telemetry with each device's alarm marker: a refreshing table, or one JSON object per sample");
  std::string count_text;
  watch->add_option("--count", count_text, "Stop after N telemetry samples (alarm samples are not counted)")->type_name("N");
  watch->add_flag("--low-rate", g.low_rate,
                  "The low-rate topics pmu/low_rate/*: at most one sample per device and packet per the service's "
                  "low_rate_period (1 s by default), for slow links");
  app.add_subcommand("list", "PMUs the service knows, with health");
  app.add_subcommand("info", "Serial number, firmware and features");
  app.add_subcommand("health", "Link, bus and device health");
  auto* alarms = app.add_subcommand("alarms", "Alarms that are active or wait for acknowledgement");
  auto* alarms_ack = alarms->add_subcommand(
      "ack", "Acknowledge an alarm (a PMU's by default, chosen as for commands; exit 0 COMPLETED, 1 not)");
  std::string ack_code, ack_kind = "pmu";
  alarms_ack->add_option("code", ack_code, "The alarm's code, e.g. thermal_shutdown")->required();
  alarms_ack->add_option("--kind", ack_kind,
                         "Whose alarm: pmu (default), battery or mppt (--address: the node or device id), bus "
                         "(--bus)");
  app.add_subcommand("preflight", "Whether the vehicle may fly, and every reason it may not (exit 0 ready, 1 not)");
  app.add_subcommand("energy", "Power per output, generator power, energy used and endurance of each battery");
  auto* config = app.add_subcommand("config", "Stored parameters");
  config->require_subcommand(1);
  auto* config_get = config->add_subcommand("get", "Show the stored parameters (or one)");
  std::string parameter;
  config_get->add_option("param", parameter, "A parameter name, e.g. avionics_voltage");
  auto* config_set = config->add_subcommand("set", "Set a stored parameter; verified by reading it back");
  std::string set_param, set_value;
  std::string parameter_names;
  for (const auto& spec : pmu::codec::parameter_table())
    parameter_names += (parameter_names.empty() ? "" : ", ") + std::string(spec.name);
  config_set->add_option("param", set_param, parameter_names)->required();
  config_set->add_option("value", set_value, "Value in the parameter's unit (V, s, degC, a number); a mask: names a,b or none, or a number")->required();

  auto* config_snapshot = config->add_subcommand(
      "snapshot", "Write the PMU's configuration to a file (- for stdout): what `config apply` reads back");
  std::string config_file;
  bool force = false;
  config_snapshot->add_option("file", config_file, "The file to write; an existing one is kept unless --force")
      ->required();
  config_snapshot->add_flag("--force", force, "Replace an existing file");
  auto* config_diff = config->add_subcommand(
      "diff", "Compare the PMU with a configuration file (exit 0 equal, 1 different, 2 bad file, 3 no answer)");
  config_diff->add_option("file", config_file,
                          "A file written by `config snapshot` or by hand; without it the service's baseline of "
                          "the PMU (pmu-service.yaml `baseline:`)");
  auto* config_apply = config->add_subcommand(
      "apply", "Write what differs from a configuration file, verified, in a safe order; undone on a failure");
  bool dry_run = false;
  config_apply->add_option("file", config_file, "A file written by `config snapshot` or by hand")->required();
  config_apply->add_flag("--dry-run", dry_run, "Check the file and print the changes in order; send nothing");
  bool other_unit = false;
  config_apply->add_flag("--other-unit", other_unit,
                         "Apply a file read from another unit (its device.serial is not this PMU's); refused "
                         "without it");

  bool confirm = false;
  app.add_flag("--confirm", confirm, "Confirm a command the safety policy guards (avionics off, reset, engine start...)");
  auto* outputs = app.add_subcommand(
      "outputs", "Output states (" + pmu::codec::names_of(pmu::codec::kOutputNames, pmu::codec::output_bit::All, ", ") + ")");
  outputs->require_subcommand(1);
  auto* outputs_get = outputs->add_subcommand("get", "Read the output states from the PMU");
  std::vector<std::string> output_names;
  auto* outputs_set = outputs->add_subcommand("set", "Set exactly these outputs on (the others off)");
  outputs_set->add_option("names", output_names, "Outputs to have on (or none)")->required();
  auto* outputs_enable = outputs->add_subcommand("enable", "Switch these outputs on");
  outputs_enable->add_option("names", output_names, "Outputs")->required();
  auto* outputs_disable = outputs->add_subcommand("disable", "Switch these outputs off");
  outputs_disable->add_option("names", output_names, "Outputs")->required();
  auto* generation = app.add_subcommand("generation", "Electrical power generation on|off");
  std::string on_off;
  generation->add_option("state", on_off, "on or off")->required()->check(CLI::IsMember({"on", "off"}));
  auto* engine = app.add_subcommand(
      "engine",
      "Engine start (verified by the generator speed) | stop (0x25: stops the starter cranking; a running engine "
      "keeps running, no PMU command stops it)");
  std::string start_stop;
  engine
      ->add_option("action", start_stop,
                   "start: crank until the engine runs; stop: stop the starter cranking (not a running engine)")
      ->required()
      ->check(CLI::IsMember({"start", "stop"}));
  auto* reset = app.add_subcommand("reset", "Restart the PMU (outputs to power-up state, energies to zero)");
  auto* measure = app.add_subcommand("measure", "Ask for measurements now (0x0F; firmware 1.14+)");
  std::vector<std::string> groups;
  measure->add_option("groups", groups,
                      pmu::codec::names_of(pmu::codec::kGroupNames, pmu::codec::group_bit::All, ", ") + " (default all)");

  auto* decode = app.add_subcommand("decode", "Decode a candump log (-L or screen format) offline");
  std::string path = "-";
  std::string firmware;
  decode->add_option("file", path, "Log file, or - for standard input")->capture_default_str();
  decode->add_option("--firmware", firmware,
                     "Firmware X.Y assumed for devices whose firmware reply is not in the log "
                     "(default: current, 1.17)");
  std::string mcap_out;
  decode->add_option("--mcap", mcap_out,
                     "Write the PMU telemetry frames as an MCAP file with the channels of `record` "
                     "(candump -L logs: the log time is the frame's timestamp) instead of printing them; "
                     "a FIFO or a character device is written in place, - is standard output");

  auto* record = app.add_subcommand(
      "record", "Record the topics into an MCAP file (Foxglove, Lichtblick, PlotJuggler) until Ctrl-C or SIGTERM");
  std::string record_path;
  record->add_option("file", record_path,
                     "The MCAP file (a regular file is replaced when the recording ends), a FIFO or a "
                     "character device (written in place), or - for standard output")
      ->required();
  std::vector<std::string> record_topics;
  record->add_option("--topic", record_topics,
                     "Only this topic (pmu/voltages or voltages; also low_rate/..., command, command_reply); "
                     "repeat for more (default: telemetry, state, health, battery and MPPT topics)")
      ->allow_extra_args(false);

  auto* serve = app.add_subcommand(
      "serve", "Serve the topics live to Foxglove or Lichtblick (Foxglove WebSocket protocol) until Ctrl-C or SIGTERM");
  std::string serve_listen = "127.0.0.1", serve_port = "8765", serve_queue = "1024";
  serve->add_option("--listen", serve_listen,
                    "IP address to listen on (0.0.0.0: every interface; there is no authentication; a web page "
                    "served over https needs --tls-cert for a remote address)")
      ->type_name("ADDR")
      ->capture_default_str();
  serve->add_option("--port", serve_port, "TCP port (Foxglove's default)")->type_name("N")->capture_default_str();
  serve->add_option("--client-queue", serve_queue,
                    "kB held for a client that does not read; beyond, its messages are dropped")
      ->type_name("KB")
      ->capture_default_str();
  std::vector<std::string> serve_topics;
  serve->add_option("--topic", serve_topics, "Only this topic, as for record; repeat for more (default: record's)")
      ->type_name("NAME")
      ->allow_extra_args(false);
  std::vector<std::string> serve_origins;
  serve->add_option("--allow-origin", serve_origins,
                    "Also let pages of this origin connect (scheme://host[:port], exactly; '*': every page); "
                    "repeat for more (default: the Foxglove app, the Foxglove and Lichtblick desktop apps, pages "
                    "on localhost, and clients that send no Origin)")
      ->type_name("ORIGIN")
      ->allow_extra_args(false);
  std::string serve_cert, serve_key;
  serve->add_option("--tls-cert", serve_cert, "Serve wss:// with this certificate (chain), PEM; with --tls-key")
      ->type_name("FILE");
  serve->add_option("--tls-key", serve_key, "The certificate's private key, PEM, without a passphrase")
      ->type_name("FILE");

  // CLI11 reads "-inf" or "-nan" as short options (-i...), so `config set avionics_voltage -inf`
  // would say "value is required". No option of pmuctl looks like that, and no value can be
  // infinite or NaN: say so here.
  const bool json_asked = std::any_of(argv + 1, argv + argc, [](const char* a) { return std::strcmp(a, "--json") == 0; });
  for (int i = 1; i < argc; ++i) {
    char* end = nullptr;
    const double v = argv[i][0] == '-' && std::isalpha(static_cast<unsigned char>(argv[i][1])) ? std::strtod(argv[i], &end) : 0;
    if (end && *end == '\0' && !std::isfinite(v))
      return pmu::tools::fail(json_asked, pmu::tools::ExitStatus::BadUsage,
                              std::string("'") + argv[i] + "' is not a finite number (a value is a number in the "
                              "parameter's unit)");
  }
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    // app.exit prints the help or the reason; bad usage is exit status 2 (the man page),
    // not CLI11's own codes (105 for a value out of range).
    return app.exit(e) == 0 ? 0 : 2;
  }
  if (address >= 0) g.address = static_cast<std::uint16_t>(address);
  if (!timeout.empty()) {
    const auto t = pmu::tools::parse_seconds("--timeout", timeout);
    if (const auto* why = std::get_if<std::string>(&t)) return pmu::tools::fail(g, pmu::tools::ExitStatus::BadUsage, *why);
    g.timeout = std::get<double>(t);
  }
  long count = 0;
  if (!count_text.empty()) {
    const auto n = pmu::tools::parse_count("--count", count_text);
    if (const auto* why = std::get_if<std::string>(&n)) return pmu::tools::fail(g, pmu::tools::ExitStatus::BadUsage, *why);
    count = std::get<long>(n);
  }

  if (*decode) {
    pmu::tools::DecodeOptions options;
    options.json = g.json;
    if (!firmware.empty()) {
      options.firmware = pmu::codec::parse_firmware(firmware);
      if (!options.firmware) {
        std::fprintf(stderr, "pmuctl decode: --firmware '%s' is not a version like 1.16\n", firmware.c_str());
        return 2;
      }
    }
    if (!mcap_out.empty()) return pmu::tools::run_decode_mcap(path, mcap_out, options.firmware);
    return run_decode(path, options);
  }
  {
    const int kind = !*engine ? -1 : start_stop == "start" ? int{pmu::v5::ENGINE_START} : int{pmu::v5::ENGINE_STOP};
    if (const auto why = pmu::tools::broadcast_refusal(g, kind); !why.empty())
      return pmu::tools::fail(g, pmu::tools::ExitStatus::BadUsage, why);
  }
  if (*config_set && !pmu::codec::parameter_from_name(set_param)) {
    // The two fields of pmu::v5::Config that are not stored parameters have verbs of their own.
    if (set_param == "outputs")
      return pmu::tools::fail(g, pmu::tools::ExitStatus::BadUsage,
                              "outputs are not a stored parameter: switch them with `pmuctl outputs set|enable|disable "
                              "NAME...` (their state at power-up is the parameter power_up_state)");
    if (set_param == "generation_enabled")
      return pmu::tools::fail(g, pmu::tools::ExitStatus::BadUsage,
                              "generation is not a stored parameter: switch it with `pmuctl generation on|off`");
    return pmu::tools::fail(g, pmu::tools::ExitStatus::BadUsage,
                            "unknown parameter '" + pmu::service::printable(set_param) + "' (parameters: " +
                                parameter_names + ")");
  }
  pmu::tools::ServeOptions serve_options;
  if (*serve) {
    auto why = pmu::tools::parse_serve_options(serve_listen, serve_port, serve_queue, serve_options);
    if (why.empty()) why = pmu::tools::parse_serve_access(serve_origins, serve_cert, serve_key, serve_options);
    if (!why.empty()) {
      std::fprintf(stderr, "pmuctl serve: %s\n", why.c_str());
      return 2;
    }
  }
  if (!setup_security(g, security_dir, identity)) return 2;
  if (!setup_vehicle(g, vehicle_option, vehicle)) return 2;
  if (!pmu::tools::resolve_network_options(network, pmu::dds::system_lookup(), !g.security.empty(), g.network))
    return 2;
  // Over a radio link a ground watch reads the low-rate topics, and the agent keeps one
  // worker: every ground participant is one more that every aircraft sends its endpoints to
  // and repairs them for (link_profile.hpp).
  if (g.network.link.low_rate_watch) g.low_rate = true;
  if (g.network.link.agent_workers > 0 && workers_option->count() == 0) agent_workers = g.network.link.agent_workers;
  // Calls that end by themselves go through the agent; those that run until stopped keep a
  // participant of their own anyway.
  const bool agent_serves = !*agent && !*watch && !*record && !*serve;
  const bool engine_stop = *engine && start_stop == "stop";
  // The caller's wait: --timeout, else the verb's default (pmuctl(1)), from the call's start.
  const bool reads_state = app.got_subcommand("list") || app.got_subcommand("info") ||
                           app.got_subcommand("health") || (*alarms && !*alarms_ack) ||
                           app.got_subcommand("preflight") || app.got_subcommand("energy") || *config_get;
  const double wait = g.timeout.value_or(reads_state ? 3.0 : 5.0);
  g.deadline = began + std::chrono::duration_cast<std::chrono::steady_clock::duration>(std::chrono::duration<double>(wait));
  g.deadline_ns = began_ns + static_cast<std::uint64_t>(wait * 1e9);
  if (served) {
    if (!agent_serves) {
      served->declined = "an agent serves calls that end by themselves, not watch, record, serve or agent";
      return 2;
    }
    if (served->request.engine_stop != engine_stop) {
      served->declined = served->request.engine_stop ? "it came on the stop lane and is not an engine stop"
                                                     : "it is an engine stop that did not come on the stop lane";
      return 2;
    }
    if (!pmu::tools::same_dds_settings(g, served->settings)) {
      served->declined = "its domain, QoS file, security or network options are not the agent's";
      return 2;
    }
    g.pool = &served->pool;
    // The caller's deadline, not one counted from now: the call may have waited for a worker.
    const std::uint64_t now_ns = epoch_ns_now();
    g.deadline_ns = served->request.deadline_ns;
    const auto left = std::chrono::nanoseconds(g.deadline_ns > now_ns ? g.deadline_ns - now_ns : 0);
    g.deadline = std::chrono::steady_clock::now() + std::chrono::duration_cast<std::chrono::steady_clock::duration>(left);
    if (left.count() == 0)
      return pmu::tools::fail(g, pmu::tools::ExitStatus::NoAnswer,
                              "the call's wait (--timeout) ended before the agent could run it: not run");
  } else if (agent_serves && !g.no_agent) {
    if (const auto status = pmu::tools::call_agent(pmu::tools::agent_socket_path(g.domain),
                                                   std::vector<std::string>(argv + 1, argv + argc), g.json,
                                                   {g.deadline_ns, engine_stop}))
      return *status;
  }
  try {
    if (*agent) {
      // Its calls compare their QoS file with this one, read while the environment is still the agent's own.
      g.qos_file = pmu::tools::effective_qos_file(g.qos_file);
      const std::string socket = agent_socket.empty() ? pmu::tools::agent_socket_path(g.domain) : agent_socket;
      return pmu::tools::run_agent(
          g, socket, agent_workers,
          [&g](const pmu::tools::AgentRequest& request, pmu::tools::ContextPool& pool, std::string& declined) {
            std::vector<std::string> words{"pmuctl"};
            words.insert(words.end(), request.arguments.begin(), request.arguments.end());
            std::vector<char*> args;
            for (auto& w : words) args.push_back(w.data());
            args.push_back(nullptr);
            const AgentCall call{pool, g, request, declined};
            return run_cli(static_cast<int>(words.size()), args.data(), &call);
          });
    }
    if (*watch) return pmu::tools::run_watch(g, count);
    if (*record) return pmu::tools::run_record(g, record_path, record_topics);
    if (*serve) return pmu::tools::run_serve(g, serve_options, serve_topics);
    if (app.got_subcommand("list")) return pmu::tools::run_list(g);
    if (app.got_subcommand("info")) return pmu::tools::run_info(g);
    if (app.got_subcommand("health")) return pmu::tools::run_health(g);
    if (*alarms_ack) return pmu::tools::run_alarm_ack(g, ack_code, ack_kind);
    if (app.got_subcommand("alarms")) return pmu::tools::run_alarms(g);
    if (app.got_subcommand("preflight")) return pmu::tools::run_preflight(g);
    if (app.got_subcommand("energy")) return pmu::tools::run_energy(g);
    if (*config_get) return pmu::tools::run_config_get(g, parameter);
    if (*config_snapshot) return pmu::tools::run_config_snapshot(g, config_file, force);
    if (*config_diff) return pmu::tools::run_config_diff(g, config_file);
    if (*config_apply) return pmu::tools::run_config_apply(g, config_file, dry_run, confirm, other_unit);
    pmu::tools::CommandSpec spec;
    spec.confirm = confirm;
    if (*config_set) {
      const auto parsed = pmu::tools::parse_config_value(set_param, set_value);
      if (!parsed.value) return pmu::tools::fail(g, pmu::tools::ExitStatus::BadUsage, parsed.error);
      spec.value = *parsed.value;
      spec.kind = pmu::v5::SET_PARAMETER;
      spec.parameter = set_param;
      return pmu::tools::run_command(g, spec);
    }
    if (*outputs_get) {
      spec.kind = pmu::v5::GET;
      spec.parameter = "outputs";
      return pmu::tools::run_command(g, spec);
    }
    if (*outputs_set || *outputs_enable || *outputs_disable) {
      if (!pmu::tools::output_mask(output_names, spec.outputs)) return 2;
      spec.kind = *outputs_set ? pmu::v5::SET_OUTPUTS : *outputs_enable ? pmu::v5::ENABLE_OUTPUTS : pmu::v5::DISABLE_OUTPUTS;
      return pmu::tools::run_command(g, spec);
    }
    if (*generation) {
      spec.kind = pmu::v5::SET_GENERATION;
      spec.enable = on_off == "on";
      return pmu::tools::run_command(g, spec);
    }
    if (*engine) {
      spec.kind = start_stop == "start" ? pmu::v5::ENGINE_START : pmu::v5::ENGINE_STOP;
      return pmu::tools::run_command(g, spec);
    }
    if (*reset) {
      spec.kind = pmu::v5::RESET;
      return pmu::tools::run_command(g, spec);
    }
    if (*measure) {
      if (!pmu::tools::group_mask(groups, spec.groups)) return 2;
      spec.kind = pmu::v5::REQUEST_MEASUREMENTS;
      return pmu::tools::run_command(g, spec);
    }
  } catch (const pmu::dds::PartitionNotGranted& e) {
    // A partition is a vehicle (service/vehicle.hpp): say it in the operator's terms.
    std::fprintf(stderr, "pmuctl: %s\n", e.what());
    if (!g.vehicle)
      std::fprintf(stderr, "pmuctl: without --vehicle pmuctl reads every vehicle (partitions \"\" and \"*\") and "
                           "commands the unnamed vehicle; this identity is confined to some vehicles: name one "
                           "of them with --vehicle\n");
    else
      std::fprintf(stderr, "pmuctl: %s is not one of this identity's vehicles\n",
                   g.vehicle->empty() ? "the unnamed vehicle" : ("vehicle " + *g.vehicle).c_str());
    return 2;
  } catch (const std::exception& e) {
    return pmu::tools::fail(g, pmu::tools::ExitStatus::BadUsage, e.what());
  }
  return 2;
}

}  // namespace

int main(int argc, char** argv) { return run_cli(argc, argv, nullptr); }
