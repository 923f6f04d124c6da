// pmuctl: the operator's command line (interface.md section 3.2): the DDS verbs that read
// what pmu-service publishes, and the offline decoder for candump logs.
//
// run_cli keeps the global options (call/global_command_line.hpp), the order of the checks,
// the hand-off to `pmuctl agent` and the dispatch; each verb file adds its own subcommands
// and options and runs them (verbs/verb.hpp).

#include <CLI/CLI.hpp>
#include <algorithm>
#include <cctype>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <memory>
#include <string>
#include <vector>

#include "pmu/idl/command.h"
#include "pmu/version.hpp"
#include "pmuctl/agent/agent_client.hpp"
#include "pmuctl/agent/agent_request.hpp"
#include "pmuctl/agent/agent_server.hpp"
#include "pmuctl/call/context_lease.hpp"
#include "pmuctl/call/exit_status.hpp"
#include "pmuctl/call/global_command_line.hpp"
#include "pmuctl/decode/decode_verb.hpp"
#include "pmuctl/record/record_verb.hpp"
#include "pmuctl/serve/serve_verb.hpp"
#include "pmuctl/verbs/alarm_verbs.hpp"
#include "pmuctl/verbs/command_verbs.hpp"
#include "pmuctl/verbs/config_file_verbs.hpp"
#include "pmuctl/verbs/energy_verb.hpp"
#include "pmuctl/verbs/preflight_verb.hpp"
#include "pmuctl/verbs/role_verbs.hpp"
#include "pmuctl/verbs/state_verbs.hpp"

namespace {

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
  return static_cast<std::uint64_t>(
      std::chrono::duration_cast<std::chrono::nanoseconds>(std::chrono::system_clock::now().time_since_epoch()).count());
}

// CLI11 reads "-inf" or "-nan" as short options (-i...), so `config set avionics_voltage -inf`
// would say "value is required". No option of pmuctl looks like that, and no value can be
// infinite or NaN: say so before parsing. The argument, or null when there is none.
const char* infinite_argument(int argc, char** argv) {
  for (int i = 1; i < argc; ++i) {
    char* end = nullptr;
    const double v =
        argv[i][0] == '-' && std::isalpha(static_cast<unsigned char>(argv[i][1])) ? std::strtod(argv[i], &end) : 0;
    if (end && *end == '\0' && !std::isfinite(v)) return argv[i];
  }
  return nullptr;
}

int run_cli(int argc, char** argv, const AgentCall* served);

// pmuctl agent [--socket PATH] [--workers N]: runs the calls made on this host through
// run_cli, each with the agent's participants (agent_server.hpp).
class AgentVerb : public pmu::tools::Verb {
 public:
  explicit AgentVerb(CLI::App& app) {
    agent_ = app.add_subcommand(
        "agent",
        "Keep this host's DDS participants for the pmuctl calls made on it (a ground station on a radio "
        "link) until Ctrl-C or SIGTERM");
    agent_
        ->add_option("--socket", socket_,
                     "The socket calls find it at (default: $PMU_AGENT_SOCKET, else $XDG_RUNTIME_DIR/pmu-dds/"
                     "agent-DOMAIN.sock, else /run/pmu-dds/agent-DOMAIN.sock)")
        ->type_name("PATH");
    workers_option_ =
        agent_
            ->add_option(
                "--workers", workers_,
                "Calls served at once, each by a process with its own DDS participant (default 4; 1 with --link "
                "radio without a Discovery Server), besides one "
                "for engine stops, which never wait. Calls go to the first while it keeps up; the next takes "
                "one when all before it have been on theirs for 5 s, so a call that waits for a silent "
                "aircraft holds up no other for longer")
            ->check(CLI::Range(1, 16));
  }
  bool chosen() const override { return agent_->parsed(); }
  // It runs other calls until stopped.
  bool ends_by_itself() const override { return false; }
  int run(pmu::tools::GlobalOptions& g) override {
    // Over a radio link the agent keeps one worker: every ground participant is one more that
    // every aircraft sends its endpoints to and repairs them for (link_profile.hpp).
    if (g.network.link.agent_workers > 0 && workers_option_->count() == 0) workers_ = g.network.link.agent_workers;
    // Its calls compare their QoS file with this one, read while the environment is still the agent's own.
    g.qos_file = pmu::tools::effective_qos_file(g.qos_file);
    const std::string socket = socket_.empty() ? pmu::tools::agent_socket_path(g.domain) : socket_;
    return pmu::tools::run_agent(
        g, socket, workers_,
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

 private:
  CLI::App* agent_;
  std::string socket_;
  int workers_ = 4;
  const CLI::Option* workers_option_;
};

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
  pmu::tools::GlobalOptionText given;
  pmu::tools::add_global_options(app, g, given);

  // In the order of the help's list of subcommands.
  std::vector<std::unique_ptr<pmu::tools::Verb>> verbs;
  verbs.push_back(std::make_unique<AgentVerb>(app));
  verbs.push_back(pmu::tools::add_state_verbs(app, g));
  verbs.push_back(pmu::tools::add_alarm_verbs(app));
  verbs.push_back(pmu::tools::add_preflight_verb(app));
  verbs.push_back(pmu::tools::add_role_verbs(app));
  verbs.push_back(pmu::tools::add_energy_verb(app));
  auto* config = app.add_subcommand("config", "Stored parameters");
  config->require_subcommand(1);
  verbs.push_back(pmu::tools::add_config_get(*config));
  verbs.push_back(pmu::tools::add_config_set(*config, given.confirm));
  verbs.push_back(pmu::tools::add_config_file_verbs(*config, given.confirm));
  verbs.push_back(pmu::tools::add_command_verbs(app, given.confirm));
  verbs.push_back(pmu::tools::add_decode_verb(app));
  verbs.push_back(pmu::tools::add_record_verb(app));
  verbs.push_back(pmu::tools::add_serve_verb(app));

  if (const char* infinite = infinite_argument(argc, argv)) {
    const bool json_asked =
        std::any_of(argv + 1, argv + argc, [](const char* a) { return std::strcmp(a, "--json") == 0; });
    return pmu::tools::fail(json_asked, pmu::tools::ExitStatus::BadUsage,
                            std::string("'") + infinite +
                                "' is not a finite number (a value is a number in the "
                                "parameter's unit)");
  }
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    // app.exit prints the help or the reason; bad usage is exit status 2 (the man page),
    // not CLI11's own codes (105 for a value out of range).
    return app.exit(e) == 0 ? 0 : 2;
  }
  if (const auto status = pmu::tools::take_target_and_wait(g, given)) return *status;
  pmu::tools::Verb* verb = nullptr;
  for (const auto& v : verbs)
    if (v->chosen()) verb = v.get();
  if (!verb) return 2;  // require_subcommand(1): never
  if (const auto status = verb->take_values(g)) return *status;
  const int kind = verb->command_kind();
  if (const auto why = pmu::tools::broadcast_refusal(g, kind); !why.empty())
    return pmu::tools::fail(g, pmu::tools::ExitStatus::BadUsage, why);
  if (const auto status = verb->check(g)) return *status;
  if (!pmu::tools::resolve_identity_and_network(g, given)) return 2;
  // Over a radio link a ground watch reads the low-rate topics: every ground participant is
  // one more that every aircraft sends its endpoints to and repairs them for (link_profile.hpp).
  if (g.network.link.low_rate_watch) g.low_rate = true;
  // Calls that end by themselves go through the agent; those that run until stopped keep a
  // participant of their own anyway.
  const bool agent_serves = verb->ends_by_itself();
  const bool engine_stop = kind == pmu::v5::ENGINE_STOP;
  // The caller's wait: --timeout, else the verb's default (pmuctl(1)), from the call's start.
  const double wait = g.timeout.value_or(verb->reads_state() ? 3.0 : 5.0);
  g.deadline =
      began + std::chrono::duration_cast<std::chrono::steady_clock::duration>(std::chrono::duration<double>(wait));
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
    g.deadline =
        std::chrono::steady_clock::now() + std::chrono::duration_cast<std::chrono::steady_clock::duration>(left);
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
    return verb->run(g);
  } catch (const pmu::dds::PartitionNotGranted& e) {
    // A partition is a vehicle (pmu/dds_settings/vehicle.hpp): say it in the operator's terms.
    std::fprintf(stderr, "pmuctl: %s\n", e.what());
    if (!g.vehicle)
      std::fprintf(stderr,
                   "pmuctl: without --vehicle pmuctl reads every vehicle (partitions \"\" and \"*\") and "
                   "commands the unnamed vehicle; this identity is confined to some vehicles: name one "
                   "of them with --vehicle\n");
    else
      std::fprintf(stderr, "pmuctl: %s is not one of this identity's vehicles\n",
                   g.vehicle->empty() ? "the unnamed vehicle" : ("vehicle " + *g.vehicle).c_str());
    return 2;
  } catch (const std::exception& e) {
    return pmu::tools::fail(g, pmu::tools::ExitStatus::BadUsage, e.what());
  }
}

}  // namespace

int main(int argc, char** argv) { return run_cli(argc, argv, nullptr); }
