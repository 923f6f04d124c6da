#include "pmu/dispatch/command_plan.hpp"

#include <cstdio>
#include <memory>

#include "pmu/codec/encode.hpp"
#include "pmu/codec/messages.hpp"

namespace pmu::service {
namespace {

using codec::PacketId;

std::string mask_text(std::uint8_t mask) {
  const std::string s = codec::names_of(codec::kOutputNames, mask);
  return s.empty() ? "none" : s;
}

// The table: one description per kind (command_plan.hpp says how a run reads them).
struct Table {
  std::uint16_t a;  // the device's address
  const DeviceFacts& device;

  CommandPlan operator()(const action::Get& g) const {
    CommandPlan p = get(g.packet);
    p.check = [](const codec::PmuMessage* m) -> Verdict {
      if (const auto* v = std::get_if<codec::ParameterValue>(&m->payload))
        return {CommandResult::Completed, "", v->value, ""};
      if (const auto* out = std::get_if<codec::OutputStates>(&m->payload))
        return {CommandResult::Completed, "", out->mask, mask_text(out->mask)};
      if (const auto* gen = std::get_if<codec::GenerationState>(&m->payload))
        return {CommandResult::Completed, "", gen->enabled ? 1 : 0, gen->enabled ? "on" : "off"};
      return {CommandResult::Completed, "published on pmu/" + std::string(codec::packet_name(m->packet)), {}, ""};
    };
    return p;
  }

  CommandPlan operator()(const action::SetParameter& set) const {
    const codec::Parameter param = set.parameter;
    const std::uint32_t raw = set.raw;
    CommandPlan p;
    p.frame = *codec::encode_parameter_reply(param, raw, a);
    p.read_back = CommandPlan::ReadBack{codec::spec_of(param).packet, a};
    const bool moves = param == codec::Parameter::CanAddress && raw != a;
    if (moves) {
      // The unit answers at its new address at once: read back there.
      const auto moved_to = static_cast<std::uint16_t>(raw);
      p.read_back->address = moved_to;
      p.alias = moved_to;
      p.on_completed = [moved_to](DeviceSession& s) {
        s.move_to(moved_to, DeviceSession::MoveCause::Commanded, s.now());
      };
    }
    // The audit line and the reply say both addresses: the operator's next command uses the new one.
    const std::string done = moves ? "moved from address " + std::to_string(a) + " to " + std::to_string(raw) +
                                         ": address it as " + std::to_string(raw) + " from now on"
                                   : std::string();
    p.check = [param, raw, done](const codec::PmuMessage* m) -> Verdict {
      const auto* got = std::get_if<codec::ParameterValue>(&m->payload);
      const double want = codec::parameter_value(param, raw);
      if (got && got->raw == raw) return {CommandResult::Completed, done, want, ""};
      char buf[128];
      std::snprintf(buf, sizeof buf, "device reports %g after the set, not %g", got ? got->value : -1.0, want);
      return {CommandResult::Failed, buf, got ? std::optional<double>(got->value) : std::nullopt, ""};
    };
    return p;
  }

  CommandPlan operator()(const action::SetOutputs& o) const {
    return outputs(*codec::encode_set_outputs(o.mask, a), [want = o.mask](std::uint8_t on) { return on == want; });
  }
  CommandPlan operator()(const action::EnableOutputs& o) const {
    return outputs(*codec::encode_enable_outputs(o.mask, a),
                   [want = o.mask](std::uint8_t on) { return (on & want) == want; });
  }
  CommandPlan operator()(const action::DisableOutputs& o) const {
    return outputs(*codec::encode_disable_outputs(o.mask, a),
                   [off = o.mask](std::uint8_t on) { return (on & off) == 0; });
  }

  CommandPlan operator()(const action::SetGeneration& g) const {
    CommandPlan p;
    p.frame = *codec::encode_generation(g.enable, a);
    p.read_back = CommandPlan::ReadBack{PacketId::Generation, a};
    p.check = [enable = g.enable](const codec::PmuMessage* m) -> Verdict {
      const auto* got = std::get_if<codec::GenerationState>(&m->payload);
      if (got && got->enabled == enable) return {CommandResult::Completed, "", enable ? 1 : 0, enable ? "on" : "off"};
      return {CommandResult::Failed, std::string("generation still ") + (got && got->enabled ? "on" : "off"), {}, ""};
    };
    return p;
  }

  CommandPlan operator()(const action::RequestMeasurements& m) const {
    std::uint8_t first = 0;
    while (!(m.groups & (1u << first))) ++first;
    CommandPlan p;
    p.frame = *codec::encode_measurement_request(m.groups, a, device.firmware);
    p.what = "measurement request";
    p.answer = static_cast<PacketId>(first);  // the device sends the groups in id order
    p.check = done("measurements published on their topics");
    return p;
  }

  CommandPlan operator()(const action::EngineStart&) const {
    char buf[96];
    std::snprintf(buf, sizeof buf, "start sent; the starter cranks for up to %.1f s", device.cranking_time);
    CommandPlan p;
    p.frame = *codec::encode_engine_start(a);
    p.what = "engine start";
    p.check = done(buf);
    return p;
  }

  CommandPlan operator()(const action::EngineStop&) const {
    CommandPlan p;
    p.frame = *codec::encode_engine_stop(a);
    p.what = "engine stop";
    p.urgent = true;  // safety first: not behind whatever the device has queued or in flight, never expired
    p.check = done("stop sent");
    return p;
  }

  CommandPlan operator()(const action::Reset&) const {
    CommandPlan p;
    p.frame = *codec::encode_reset(a);
    p.what = "reset";
    p.check = done("reset sent; re-reading the device");
    // Outputs went to S0 and energies to zero: read everything again.
    p.on_completed = [](DeviceSession& s) { s.reread(s.now()); };
    return p;
  }

  CommandPlan operator()(const action::GetSerial&) const {
    CommandPlan p = get(PacketId::Serial);
    p.check = [](const codec::PmuMessage* m) -> Verdict {
      const auto* s = std::get_if<codec::SerialNumber>(&m->payload);
      if (!s) return {CommandResult::Failed, "the answer carries no serial number", {}, ""};
      return {CommandResult::Completed, "", s->serial_number, std::to_string(s->serial_number)};
    };
    return p;
  }

  CommandPlan operator()(const action::GetFirmware&) const {
    CommandPlan p = get(PacketId::Firmware);
    p.check = [](const codec::PmuMessage* m) -> Verdict {
      const auto* f = std::get_if<codec::FirmwareInfo>(&m->payload);
      if (!f) return {CommandResult::Failed, "the answer carries no firmware version", {}, ""};
      char buf[64];
      std::snprintf(buf, sizeof buf, "%u.%u built %04u-%02u-%02u", f->firmware_major, f->firmware_minor, f->build_year,
                    f->build_month, f->build_day);
      return {CommandResult::Completed, "", f->firmware_major + f->firmware_minor / 100.0, buf};
    };
    return p;
  }

 private:
  // A zero-length get, answered by the same packet and safe to repeat.
  CommandPlan get(PacketId packet) const {
    CommandPlan p;
    p.frame = *codec::encode_get(packet, a);
    p.what = "get";
    p.answer = packet;
    p.idempotent = true;
    return p;
  }

  // 0x20/0x21/0x22, verified by reading 0x20 back: `ok` judges the outputs now on.
  CommandPlan outputs(const codec::CanFrame& frame, std::function<bool(std::uint8_t)> ok) const {
    CommandPlan p;
    p.frame = frame;
    p.read_back = CommandPlan::ReadBack{PacketId::Outputs, a};
    p.check = [ok = std::move(ok)](const codec::PmuMessage* m) -> Verdict {
      const auto* got = std::get_if<codec::OutputStates>(&m->payload);
      const std::uint8_t on = got ? got->mask : 0;
      if (got && ok(on)) return {CommandResult::Completed, "", on, "on: " + mask_text(on)};
      return {CommandResult::Failed, "outputs on after the command: " + mask_text(on), on, "on: " + mask_text(on)};
    };
    return p;
  }

  // A frame the device does not answer: sending it is the whole command.
  static std::function<Verdict(const codec::PmuMessage*)> done(std::string reason) {
    return [reason = std::move(reason)](const codec::PmuMessage*) {
      return Verdict{CommandResult::Completed, reason, {}, ""};
    };
  }
};

}  // namespace

CommandPlan plan_command(const CommandRequest& r, const DeviceFacts& device) {
  return std::visit(Table{r.address, device}, r.action);
}

}  // namespace pmu::service
