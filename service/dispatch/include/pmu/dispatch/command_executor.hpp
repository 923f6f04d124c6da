#pragma once
// Carries out one command on one device session (on the bus worker's thread): checks it
// against what the device's firmware supports, then sends
// it and verifies the result, replying exactly once with a final result. It works on parsed
// requests only (command.hpp): every value is already in range and in wire units.
//
//   sets        send, read the value back, COMPLETED only if the device reports it
//   outputs     0x20/0x21/0x22, then read 0x20 back and check the bits
//   generation  0x23, then read it back
//   gets        zero-length get, retried (idempotent), TIMEOUT when the device is silent
//   measure     0x0F (firmware 1.14+), COMPLETED when the first requested packet arrives
//   engine stop sent ahead of anything queued for the device
//   reset       sent, then identity and every stored value are read again
// Nothing reaches the bus for a request that fails the checks (REJECTED / UNSUPPORTED).
// Each kind is a description in one table (command_plan.hpp), run by one generic runner.
//
// Lifetime: the steps of a command keep a reference to `session` and are held by its request
// queue, so they never outlive it. `reply` must stay callable until it is called; it is not
// called when the session is destroyed with the command still queued.
// Threads: execute_command() on the thread of the bus worker that owns `session`; `reply` is
// called on that thread.

#include <functional>
#include <optional>

#include "pmu/command/command.hpp"
#include "pmu/config/config.hpp"
#include "pmu/dispatch/command_plan.hpp"
#include "pmu/session/device_session.hpp"

namespace pmu::service {

// What the device's firmware decides (parse_command checked everything else): a final
// UNSUPPORTED reply when `fw` lacks what `r` asks for, nullopt otherwise.
std::optional<CommandReplyData> check_firmware(const CommandRequest& r, std::optional<codec::FirmwareVersion> fw);

// Checks the firmware, then runs the command on `session`. `r.expires` bounds how long the
// first frame may wait in the device's queue. `reply` is called exactly once, final.
void execute_command(DeviceSession& session, const CommandRequest& r, SteadyTime now, const Timeouts& timeouts,
                     ReplyFn reply);

}  // namespace pmu::service
