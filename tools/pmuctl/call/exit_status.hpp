#pragma once
// pmuctl's exit statuses, one table for every verb (pmuctl(1), interface.md section 3.2), and
// the one way a verb ends in failure: the message on stderr and, with --json, exactly one
// JSON line on stdout, so that a script reading lines always gets one per result.
//
//   return fail(o, ExitStatus::NoAnswer, "no pmu-service on domain 7");
//   // stderr: pmuctl: no pmu-service on domain 7
//   // stdout (--json): {"error":"no pmu-service on domain 7","exit_status":3}

#include <string>

namespace pmu::tools {

struct GlobalOptions;

enum class ExitStatus : int {
  Ok = 0,        // the state was read; the command COMPLETED
  NotDone = 1,   // asked and answered, but not done: a result other than COMPLETED, fewer samples than --count
  BadUsage = 2,  // bad usage, or no such target: unknown vehicle, bus, device or parameter, a bad file
  NoAnswer = 3,  // nothing answered in time: no pmu-service on the domain, or no reply to a command
};

// Prints the failure as above and returns its status as the process's exit code.
int fail(const GlobalOptions& o, ExitStatus status, const std::string& message);
// The same without options (before they are known): JSON only when `json`.
int fail(bool json, ExitStatus status, const std::string& message);

}  // namespace pmu::tools
