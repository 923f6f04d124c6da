#include "pmu/service/command_executor.hpp"

#include <cstdio>
#include <memory>

#include "pmu/codec/encode.hpp"
#include "pmu/codec/messages.hpp"

namespace pmu::service {
namespace {

using codec::PacketId;

CommandResult result_of(const codec::EncodeError& e) {
  return e.kind == codec::EncodeErrorKind::Unsupported ? CommandResult::Unsupported : CommandResult::Rejected;
}

std::string mask_text(std::uint8_t mask) {
  const std::string s = codec::names_of(codec::kOutputNames, mask);
  return s.empty() ? "none" : s;
}

// One command in progress: the reply is sent once, whatever path ends it.
struct Run {
  CommandRequest request;
  ReplyFn reply;
  const Timeouts& timeouts;
  DeviceSession& session;
  bool replied = false;

  void finish(CommandResult result, std::string reason, std::optional<double> value = std::nullopt,
              std::string value_text = {}) {
    if (replied) return;
    replied = true;
    CommandReplyData d = make_reply(request, result, std::move(reason));
    if (value) {
      d.has_value = true;
      d.value = *value;
    }
    d.value_text = std::move(value_text);
    reply(d);
  }

  // Maps a step's failure to the final reply; true when the step succeeded.
  bool ok(const RequestOutcome& o, const char* what) {
    switch (o.status) {
      case RequestStatus::Answered:
      case RequestStatus::Sent: return true;
      case RequestStatus::Expired:
        finish(CommandResult::Rejected, "expired before it could be sent");
        return false;
      case RequestStatus::SendFailed:
        finish(CommandResult::Failed, std::string("bus refused the ") + what + ": " +
                                          std::string(transport::to_string(o.send.status)));
        return false;
      case RequestStatus::Timeout:
        finish(CommandResult::Timeout, std::string("device ") + std::to_string(request.address) + " did not answer the " +
                                           what + " after " + std::to_string(timeouts.retries + 1) + " tries");
        return false;
    }
    return false;
  }
};

Request step(const codec::CanFrame& frame, std::optional<PacketId> reply, unsigned retries,
             std::optional<SteadyTime> expires, std::function<void(const RequestOutcome&)> done) {
  Request r;
  r.frame = frame;
  r.reply = reply;
  r.retries = retries;
  r.expires = expires;
  r.done = std::move(done);
  return r;
}

}  // namespace

CommandReplyData make_reply(const CommandRequest& r, CommandResult result, std::string reason) {
  CommandReplyData d;
  d.request_id = r.request_id;
  d.bus = r.bus;
  d.address = r.address;
  d.kind = r.kind();
  d.result = result;
  d.reason = std::move(reason);
  return d;
}

CommandReplyData make_reply(const CommandSample& s, CommandResult result, std::string reason) {
  CommandReplyData d;
  d.request_id = s.request_id;
  d.bus = s.bus;
  d.address = s.address;
  d.kind = s.kind < kCommandKindCount ? static_cast<CommandKind>(s.kind) : CommandKind::Get;
  d.result = result;
  d.reason = std::move(reason);
  return d;
}

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
  const auto fw = session.firmware();
  const std::optional<SteadyTime> expires = request.expires;
  if (auto invalid = check_firmware(request, fw)) {
    reply(*invalid);
    return;
  }
  auto run = std::make_shared<Run>(Run{request, std::move(reply), timeouts, session});
  const std::uint16_t a = request.address;
  const unsigned retries = timeouts.retries;

  // Sends `first` (which expires), then reads `readback` and hands the answer to `check`,
  // which returns true when the device reports what was asked. A mismatch is read once more
  // before it counts: the protocol has no sequence numbers, so a late answer to an earlier
  // get of the same packet can arrive first. `check(m, true)` on the last read must finish.
  using Check = std::function<bool(const codec::PmuMessage&, bool last)>;
  auto set_then_read = [&](const codec::CanFrame& first, PacketId readback, std::uint16_t read_address, Check check) {
    auto read = std::make_shared<std::function<void(bool)>>();
    *read = [run, readback, read_address, retries, check, read](bool last) {
      run->session.submit_front(
          step(*codec::encode_get(readback, read_address), readback, retries, std::nullopt,
               [run, check, read, last](const RequestOutcome& r) {
                 if (!run->ok(r, "read-back")) {
                   run->session.set_alias(std::nullopt);
                   *read = nullptr;  // break the self-reference
                   return;
                 }
                 if (check(*r.reply, last) || last) {
                   *read = nullptr;
                   return;
                 }
                 (*read)(true);
               }),
          run->session.now());
    };
    session.submit(step(first, std::nullopt, 0, expires,
                        [run, read](const RequestOutcome& o) {
                          if (!run->ok(o, "command")) {
                            run->session.set_alias(std::nullopt);
                            *read = nullptr;
                            return;
                          }
                          (*read)(false);
                        }),
                   now);
  };

  switch (request.kind()) {
    case CommandKind::Get: {
      const PacketId target = std::get<action::Get>(request.action).packet;
      session.submit(step(*codec::encode_get(target, a), target, retries, expires,
                          [run](const RequestOutcome& o) {
                            if (!run->ok(o, "get")) return;
                            const auto& m = *o.reply;
                            if (const auto* p = std::get_if<codec::ParameterValue>(&m.payload))
                              return run->finish(CommandResult::Completed, "", p->value);
                            if (const auto* out = std::get_if<codec::OutputStates>(&m.payload))
                              return run->finish(CommandResult::Completed, "", out->mask, mask_text(out->mask));
                            if (const auto* g = std::get_if<codec::GenerationState>(&m.payload))
                              return run->finish(CommandResult::Completed, "", g->enabled ? 1 : 0,
                                                 g->enabled ? "on" : "off");
                            run->finish(CommandResult::Completed,
                                        "published on pmu/" + std::string(codec::packet_name(m.packet)));
                          }),
                     now);
      return;
    }
    case CommandKind::SetParameter: {
      const auto& set = std::get<action::SetParameter>(request.action);
      const codec::Parameter p = set.parameter;
      const std::uint32_t raw = set.raw;
      const auto& spec = codec::spec_of(p);
      std::uint16_t read_at = a;
      if (p == codec::Parameter::CanAddress) {
        // The unit answers at its new address at once: read back there.
        read_at = static_cast<std::uint16_t>(raw);
        session.set_alias(read_at);
      }
      set_then_read(*codec::encode_parameter_reply(p, raw, a), spec.packet, read_at,
                    [run, p, raw](const codec::PmuMessage& m, bool last) {
                      const auto* got = std::get_if<codec::ParameterValue>(&m.payload);
                      const double want = codec::parameter_value(p, raw);
                      if (got && got->raw == raw) {
                        if (p == codec::Parameter::CanAddress) run->session.readdress(static_cast<std::uint16_t>(raw));
                        run->finish(CommandResult::Completed, "", want);
                        return true;
                      }
                      if (!last) return false;
                      run->session.set_alias(std::nullopt);
                      char buf[128];
                      std::snprintf(buf, sizeof buf, "device reports %g after the set, not %g",
                                    got ? got->value : -1.0, want);
                      run->finish(CommandResult::Failed, buf, got ? std::optional<double>(got->value) : std::nullopt);
                      return false;
                    });
      return;
    }
    case CommandKind::SetOutputs:
    case CommandKind::EnableOutputs:
    case CommandKind::DisableOutputs: {
      const CommandKind kind = request.kind();
      const std::uint8_t mask = kind == CommandKind::SetOutputs      ? std::get<action::SetOutputs>(request.action).mask
                                : kind == CommandKind::EnableOutputs ? std::get<action::EnableOutputs>(request.action).mask
                                                                     : std::get<action::DisableOutputs>(request.action).mask;
      const auto frame = kind == CommandKind::SetOutputs      ? *codec::encode_set_outputs(mask, a)
                         : kind == CommandKind::EnableOutputs ? *codec::encode_enable_outputs(mask, a)
                                                              : *codec::encode_disable_outputs(mask, a);
      set_then_read(frame, PacketId::Outputs, a, [run, mask, kind](const codec::PmuMessage& m, bool last) {
        const auto* got = std::get_if<codec::OutputStates>(&m.payload);
        const std::uint8_t now_on = got ? got->mask : 0;
        const bool ok = got && (kind == CommandKind::SetOutputs      ? now_on == mask
                                : kind == CommandKind::EnableOutputs ? (now_on & mask) == mask
                                                                     : (now_on & mask) == 0);
        if (ok) {
          run->finish(CommandResult::Completed, "", now_on, "on: " + mask_text(now_on));
          return true;
        }
        if (last)
          run->finish(CommandResult::Failed, "outputs on after the command: " + mask_text(now_on), now_on,
                      "on: " + mask_text(now_on));
        return false;
      });
      return;
    }
    case CommandKind::SetGeneration: {
      const bool enable = std::get<action::SetGeneration>(request.action).enable;
      set_then_read(*codec::encode_generation(enable, a), PacketId::Generation, a,
                    [run, enable](const codec::PmuMessage& m, bool last) {
                      const auto* got = std::get_if<codec::GenerationState>(&m.payload);
                      if (got && got->enabled == enable) {
                        run->finish(CommandResult::Completed, "", enable ? 1 : 0, enable ? "on" : "off");
                        return true;
                      }
                      if (last)
                        run->finish(CommandResult::Failed,
                                    std::string("generation still ") + (got && got->enabled ? "on" : "off"));
                      return false;
                    });
      return;
    }
    case CommandKind::RequestMeasurements: {
      const std::uint8_t groups = std::get<action::RequestMeasurements>(request.action).groups;
      std::uint8_t first = 0;
      while (!(groups & (1u << first))) ++first;
      const auto reply_packet = static_cast<PacketId>(first);
      session.submit(step(*codec::encode_measurement_request(groups, a, fw), reply_packet, 0, expires,
                          [run](const RequestOutcome& o) {
                            if (run->ok(o, "measurement request"))
                              run->finish(CommandResult::Completed, "measurements published on their topics");
                          }),
                     now);
      return;
    }
    case CommandKind::EngineStart:
    case CommandKind::Reset: {
      const bool reset = request.kind() == CommandKind::Reset;
      const auto frame = reset ? *codec::encode_reset(a) : *codec::encode_engine_start(a);
      const double ct = session.config_state().value(codec::Parameter::CrankingTime);
      session.submit(step(frame, std::nullopt, 0, expires,
                          [run, reset, ct](const RequestOutcome& o) {
                            if (!run->ok(o, reset ? "reset" : "engine start")) return;
                            if (reset) {
                              // Outputs went to S0 and energies to zero: read everything again.
                              run->session.reread(run->session.now());
                              return run->finish(CommandResult::Completed, "reset sent; re-reading the device");
                            }
                            char buf[96];
                            std::snprintf(buf, sizeof buf, "start sent; the starter cranks for up to %.1f s", ct);
                            run->finish(CommandResult::Completed, buf);
                          }),
                     now);
      return;
    }
    case CommandKind::EngineStop:
      // Safety first: ahead of whatever the device has queued, and never expired.
      session.submit_front(step(*codec::encode_engine_stop(a), std::nullopt, 0, std::nullopt,
                                [run](const RequestOutcome& o) {
                                  if (run->ok(o, "engine stop")) run->finish(CommandResult::Completed, "stop sent");
                                }),
                           now);
      return;
    case CommandKind::GetSerial:
    case CommandKind::GetFirmware: {
      const bool serial = request.kind() == CommandKind::GetSerial;
      const PacketId p = serial ? PacketId::Serial : PacketId::Firmware;
      session.submit(step(*codec::encode_get(p, a), p, retries, expires,
                          [run](const RequestOutcome& o) {
                            if (!run->ok(o, "get")) return;
                            if (const auto* s = std::get_if<codec::SerialNumber>(&o.reply->payload))
                              return run->finish(CommandResult::Completed, "", s->serial_number,
                                                 std::to_string(s->serial_number));
                            const auto& f = std::get<codec::FirmwareInfo>(o.reply->payload);
                            char buf[64];
                            std::snprintf(buf, sizeof buf, "%u.%u built %04u-%02u-%02u", f.firmware_major,
                                          f.firmware_minor, f.build_year, f.build_month, f.build_day);
                            run->finish(CommandResult::Completed, "", f.firmware_major + f.firmware_minor / 100.0, buf);
                          }),
                     now);
      return;
    }
  }
}

}  // namespace pmu::service
