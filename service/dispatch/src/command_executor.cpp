#include "pmu/dispatch/command_executor.hpp"

#include "pmu/codec/encode.hpp"
#include "pmu/dispatch/command_reply.hpp"
#include "pmu/dispatch/engine_start.hpp"

namespace pmu::service {
namespace {

CommandResult result_of(const codec::EncodeError& e) {
  return e.kind == codec::EncodeErrorKind::Unsupported ? CommandResult::Unsupported : CommandResult::Rejected;
}

}  // namespace

std::optional<CommandReplyData> check_firmware(const CommandRequest& r, std::optional<codec::FirmwareVersion> fw) {
  if (const auto* set = std::get_if<action::SetParameter>(&r.action)) {
    // S0's bits depend on the firmware; the value itself was checked at the boundary.
    const auto raw = codec::to_raw(set->parameter, codec::parameter_value(set->parameter, set->raw), fw);
    if (!raw) return make_reply(r, result_of(raw.error()), raw.error().describe());
  } else if (const auto* m = std::get_if<action::RequestMeasurements>(&r.action)) {
    const auto f = codec::encode_measurement_request(m->groups, r.address, fw);
    if (!f) return make_reply(r, result_of(f.error()), f.error().describe());
  }
  return std::nullopt;
}

void execute_command(DeviceSession& session, const CommandRequest& request, SteadyTime now, const Timeouts& timeouts,
                     ReplyFn reply) {
  DeviceFacts device;
  device.firmware = session.firmware();
  device.cranking_time = session.config_state().value(codec::Parameter::CrankingTime);
  if (auto invalid = check_firmware(request, device.firmware)) {
    reply(*invalid);
    return;
  }
  if (request.kind() == CommandKind::EngineStop) session.on_engine_stop(request.request_id, now);
  if (request.kind() == CommandKind::EngineStart) {
    // One start at a time: a second would restart nothing on the unit (the starter is
    // already engaged) and its verdict would be the first one's.
    if (const auto& running = session.engine_start())
      return reply(make_reply(request, CommandResult::Denied,
                              "an engine start is in progress (request " + running->request_id + ")"));
    return run_engine_start(session, request, device, timeouts, EngineStartTiming{}, std::move(reply));
  }
  run_plan(session, request, plan_command(request, device), now, timeouts, std::move(reply));
}

}  // namespace pmu::service
