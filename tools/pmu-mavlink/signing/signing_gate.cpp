#include "signing/signing_gate.hpp"

#include "pmu/mavlink/messages.hpp"

namespace pmu::mavlink_bridge {

namespace nm = pmu::mavlink;

std::optional<FrameTarget> frame_target(const nm::Frame& frame) {
  if (const auto m = nm::decode<nm::CommandLong>(frame)) return FrameTarget{m->target_system, m->target_component};
  if (const auto m = nm::decode<nm::ParamSet>(frame)) return FrameTarget{m->target_system, m->target_component};
  if (const auto m = nm::decode<nm::ParamRequestRead>(frame)) return FrameTarget{m->target_system, m->target_component};
  if (const auto m = nm::decode<nm::ParamRequestList>(frame)) return FrameTarget{m->target_system, m->target_component};
  return std::nullopt;
}

namespace {

// Messages that ask nothing of a component: a sender's state, answers to another's requests.
// COMMAND_ACK is here though it has target fields: this component sends no command, so no
// acknowledgement is for it, and old senders leave those fields 0 (which would read as a
// broadcast).
bool asks_nothing(std::uint32_t msgid) {
  switch (msgid) {
    case nm::msgid::kHeartbeat:
    case nm::msgid::kParamValue:
    case nm::msgid::kCommandAck:
    case nm::msgid::kBatteryStatus:
    case nm::msgid::kStatustext:
    case nm::msgid::kGeneratorStatus:
    case nm::msgid::kRelayStatus: return true;
    default: return false;
  }
}

}  // namespace

bool addressed_to(const nm::Frame& frame, std::uint8_t system, std::uint8_t component) {
  if (const auto t = frame_target(frame)) {
    return (t->system == system || t->system == 0) && (t->component == component || t->component == 0);
  }
  return !asks_nothing(frame.msgid);
}

bool SigningGate::admits(const nm::Frame& frame, std::uint8_t system, std::uint8_t component, std::uint64_t now) {
  if (!link_ || !addressed_to(frame, system, component)) return true;
  return link_->verify(frame, now) == nm::Verdict::accepted;
}

bool SigningGate::authentic(const nm::Frame& frame, std::uint64_t now) {
  return !link_ || link_->verify(frame, now) == nm::Verdict::accepted;
}

}  // namespace pmu::mavlink_bridge
