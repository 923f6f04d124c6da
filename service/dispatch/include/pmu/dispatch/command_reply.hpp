#pragma once
// The final reply to a command, built in one place for every path that answers one: a
// sample that did not parse (command_service), a firmware check that refuses it
// (command_executor), a plan's verdict (command_run) and an engine start's (engine_start).

#include <string>

#include "pmu/command/command.hpp"

namespace pmu::service {

// A final reply to a parsed request `r` with `result` and `reason`.
CommandReplyData make_reply(const CommandRequest& r, CommandResult result, std::string reason);

// A final reply to a sample that did not parse (an unknown kind is answered as GET).
CommandReplyData make_reply(const CommandSample& s, CommandResult result, std::string reason);

}  // namespace pmu::service
