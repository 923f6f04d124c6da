#pragma once
// pmuctl's command verbs (interface.md section 3.2): one pmu::v5::Command, exactly one final
// pmu::v5::CommandReply. Exit status 0 only for COMPLETED (exit_status.hpp); the result and
// reason go to stderr.

#include <cstdint>
#include <string>
#include <vector>

#include "pmuctl/verbs/state_verbs.hpp"
#include "pmuctl/verbs/verb.hpp"

namespace pmu::tools {

struct CommandSpec {
  int kind = 0;  // pmu::v5::CommandKind
  std::string parameter;
  double value = 0;
  std::uint8_t outputs = 0;
  bool enable = false;
  std::uint8_t groups = 0;
  bool confirm = false;
  std::string request_id;  // empty: a new one (request_id()); an apply names its commands APPLY#N
};

int run_command(const GlobalOptions& o, const CommandSpec& spec);

// pmuctl alarms ack CODE: one pmu::v5::AlarmAck, exactly one AlarmAckReply (interface.md 1.6).
// `kind` is "pmu" (the PMU chosen as for commands), "battery", "mppt" (--bus and --address the
// node or device id) or "bus" (--bus). Exit 0 for ACK_COMPLETED, 1 otherwise, 3 no answer.
int run_alarm_ack(const GlobalOptions& o, const std::string& code, const std::string& kind);

// Why --address 65535 may not go with this command kind, or "" when it may (engine stop alone,
// or another address).
std::string broadcast_refusal(const GlobalOptions& o, int kind);

// "avionics_servo" -> bit 0 ... ; false (with a message on stderr) for an unknown name.
bool output_mask(const std::vector<std::string>& names, std::uint8_t& mask);
bool group_mask(const std::vector<std::string>& names, std::uint8_t& mask);

// config set PARAM VALUE, added to the `config` subcommand; its parameter is checked by
// Verb::check, its value when it runs. `confirm` (--confirm) is read when it runs.
std::unique_ptr<Verb> add_config_set(CLI::App& config, const bool& confirm);
// outputs, generation, engine, reset, measure: added to `app` in that order.
std::unique_ptr<Verb> add_command_verbs(CLI::App& app, const bool& confirm);

}  // namespace pmu::tools
