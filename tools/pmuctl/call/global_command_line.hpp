#pragma once
// pmuctl's global options on the command line (pmuctl(1) "Global options"): added to the
// app, then typed and checked into GlobalOptions in two steps, as run_cli orders its checks:
// the target and the wait first, the identity, vehicle and network once the verb's own values
// passed. Every bad value is exit status 2 with what and why, before anything touches DDS.
//
// Lifetime: add_global_options binds the app's options to `g` and `text`, which must outlive
// the app's parse.

#include <optional>
#include <string>

#include "pmuctl/call/global_options.hpp"
#include "pmuctl/call/network_options.hpp"

namespace CLI {
class App;
class Option;
}  // namespace CLI

namespace pmu::tools {

// The global options as given, before they are checked.
struct GlobalOptionText {
  int address = -1;  // -1: not given
  std::string timeout;
  std::string vehicle;
  const CLI::Option* vehicle_option = nullptr;  // whether --vehicle was given, "" included
  std::string security_dir, identity;
  NetworkOptions network;
  bool confirm = false;  // --confirm: the command verbs' and `config apply`'s
};

void add_global_options(CLI::App& app, GlobalOptions& g, GlobalOptionText& text);

// --address and --timeout into `g`: a status ends the call.
std::optional<int> take_target_and_wait(GlobalOptions& g, const GlobalOptionText& text);

// --security-dir/--identity, --vehicle and the network options (or their variables) into
// `g`; false, after saying why on stderr, when one is unusable.
bool resolve_identity_and_network(GlobalOptions& g, const GlobalOptionText& text);

}  // namespace pmu::tools
