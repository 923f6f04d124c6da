#pragma once
// What run_cli (main.cpp) asks of each verb file. A verb file adds its subcommands, and the
// options only they use, to the command line (add_*_verb(s) in its header); once the line is
// parsed, the chosen verb types its own values, is checked and runs. run_cli keeps the global
// options, the order of the checks, the agent hand-off and the dispatch: every bad value is
// exit status 2 before anything touches DDS (pmuctl(1)).
//
// Lifetime: a Verb keeps pointers to its subcommands, which the CLI::App it was added to owns,
// and the values of its options, which CLI11 writes into it: the app and its verbs live for
// the call, in run_cli's frame, and are used on its thread only. A reference a verb is given
// when it is added (--confirm, GlobalOptions) must outlive it.

#include <memory>
#include <optional>

namespace CLI {
class App;
}  // namespace CLI

namespace pmu::tools {

struct GlobalOptions;  // state_verbs.hpp

class Verb {
 public:
  virtual ~Verb() = default;

  // Whether the parsed command line named one of this verb's subcommands.
  virtual bool chosen() const = 0;
  // Its own option values typed once parsed, as --timeout is (watch --count): a status ends
  // the call. `decode`, which needs no DDS and no target, runs here whole.
  virtual std::optional<int> take_values(const GlobalOptions&) { return std::nullopt; }
  // The command kind an `engine` call sends (--address 65535 is an engine stop's alone); -1
  // for every other verb.
  virtual int command_kind() const { return -1; }
  // Checks made once the target options passed (config set's parameter, serve's listener):
  // a status ends the call.
  virtual std::optional<int> check(const GlobalOptions&) { return std::nullopt; }
  // Whether the call ends by itself, so that `pmuctl agent` may run it: watch, record and
  // serve run until stopped and keep a participant of their own.
  virtual bool ends_by_itself() const { return true; }
  // Whether it reads state, with 3 s to wait by default, rather than sends a command (5 s).
  virtual bool reads_state() const { return false; }
  // The verb itself: the process exit status (exit_status.hpp).
  virtual int run(GlobalOptions& g) = 0;
};

// A verb of one subcommand with no options of its own that reads state (energy, preflight):
// `name` and `description` are the subcommand's as --help shows them, `run` the whole call.
std::unique_ptr<Verb> add_state_reading_verb(CLI::App& app, const char* name, const char* description,
                                             int (*run)(const GlobalOptions&));

}  // namespace pmu::tools
