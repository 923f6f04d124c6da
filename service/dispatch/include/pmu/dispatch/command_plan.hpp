#pragma once
// A command as a description, not as code: the frame that carries it, the packet that
// answers it or reads it back, and the check that turns that answer into the final reply.
// plan_command() holds one description per kind (the table, command_plan.cpp);
// run_plan() is the one runner that carries any description out on a device session
// (command_run.cpp). A kind's behaviour is read off its description:
//
//   Get            frame  get of the packet, answered by it, retried       check: its value
//   SetParameter   frame  the value;   read back the parameter             check: same raw
//                  (CAN address: read back at the new address, which is the session's alias
//                  meanwhile; the session moves there once the check passes)
//   Set/Enable/DisableOutputs  0x20/0x21/0x22; read back 0x20              check: the bits
//   SetGeneration  0x23; read back 0x23                                    check: the state
//   RequestMeasurements  0x0F, done when the first requested packet arrives
//   Reset / EngineStop  sent, nothing to read; a reset then re-reads the device; the stop
//                  is not queued at all: out at once, to where the unit is when it is sent
//                  (DeviceSession::send_urgent), and never expires
//   EngineStart    its frame only: the start is verified by the generator speed, a run of
//                  its own (engine_start.hpp), not by one answer
//
// Steps of a run, each one Request on the session (device_session.hpp):
//   0  `frame` (behind the device's queue, with the command's expiry; when `urgent`, not
//      queued: sent at once, with no expiry)
//   1  the read-back get, ahead of the queue so nothing changes the value in between
//   2  the read-back once more when step 1's answer fails the check: the protocol has no
//      sequence numbers, so a late answer to an earlier get of the packet can come first
// A step that fails (expired, refused by the bus, unanswered) ends the run with its reason.

#include <cstdint>
#include <functional>
#include <optional>
#include <string>

#include "pmu/codec/can_frame.hpp"
#include "pmu/codec/decode.hpp"
#include "pmu/command/command.hpp"
#include "pmu/config/config.hpp"
#include "pmu/session/device_session.hpp"

namespace pmu::service {

using ReplyFn = std::function<void(const CommandReplyData&)>;

// What an answer means for the command: its final result, reason and value.
struct Verdict {
  CommandResult result = CommandResult::Completed;
  std::string reason;
  std::optional<double> value;
  std::string value_text;
};

struct CommandPlan {
  codec::CanFrame frame;                  // the command itself, encoded by the codec
  std::string what = "command";           // names step 0 in failure reasons ("did not answer the get")
  std::optional<codec::PacketId> answer;  // the packet that answers `frame` (gets, 0x0F); none for sets
  bool idempotent = false;                // `frame` is a get: retried when the device is silent
  bool urgent = false;                    // sent at once, not queued, never expired (engine stop)

  struct ReadBack {
    codec::PacketId packet;
    std::uint16_t address;
  };
  std::optional<ReadBack> read_back;  // the verification get once `frame` is sent
  // Frames from this address belong to the session while the run lasts (a CAN address
  // change answers at the new address); dropped again when the run fails.
  std::optional<std::uint16_t> alias;

  // The final answer's meaning: the read-back's answer when there is one, else `frame`'s
  // answer, else nullptr (a frame that only had to be sent).
  std::function<Verdict(const codec::PmuMessage* answer)> check;
  // Runs on the session when the verdict is COMPLETED, before the reply is sent.
  std::function<void(DeviceSession&)> on_completed;
};

// What plans depend on besides the request.
struct DeviceFacts {
  std::optional<codec::FirmwareVersion> firmware;
  double cranking_time = 0;  // s, quoted in engine start's reply
};

// The description of `r` (which passed check_firmware for `device.firmware`).
CommandPlan plan_command(const CommandRequest& r, const DeviceFacts& device);

// Carries out `plan` for `r` on `session`; `reply` is called exactly once, final.
void run_plan(DeviceSession& session, const CommandRequest& r, CommandPlan plan, SteadyTime now,
              const Timeouts& timeouts, ReplyFn reply);

}  // namespace pmu::service
