#include "program/bridge.hpp"

#include "pmu/mavlink/messages.hpp"
#include "telemetry/battery_status.hpp"
#include "telemetry/generator_status.hpp"
#include "telemetry/relay_status.hpp"

namespace pmu::mavlink_bridge {

namespace nm = pmu::mavlink;

namespace {

// Until the autopilot's HEARTBEAT is heard the component speaks as system 1, MAVLink's
// usual first vehicle; its HEARTBEAT says MAV_TYPE_BATTERY and MAV_AUTOPILOT_INVALID, so no
// ground station makes a vehicle of it meanwhile.
constexpr std::uint8_t kSystemIdUntilHeard = 1;

}  // namespace

Bridge::Bridge(const Settings& settings, std::vector<Endpoint*> endpoints, DdsInputs& inputs,
               std::optional<Signing> signing)
    : settings_(settings),
      endpoints_(std::move(endpoints)),
      inputs_(inputs),
      system_id_(settings.system_id.value_or(kSystemIdUntilHeard)),
      system_id_fixed_(settings.system_id.has_value()),
      writer_(std::make_unique<nm::FrameWriter>(system_id_, settings.component_id)),
      scheduler_(settings.intervals) {
  if (signing) {
    gate_ = SigningGate(signing->key);
    signing_clock_ = std::move(signing->clock);
  }
  other_frames_ = [](const nm::Frame& frame, const Send& send, Clock::time_point) {
    const auto command = nm::decode<nm::CommandLong>(frame);
    if (!command) return;
    nm::CommandAck ack;
    ack.command = command->command;
    ack.result = nm::mav_result::kUnsupported;
    ack.target_system = frame.sysid;
    ack.target_component = frame.compid;
    nm::Payload payload{};
    ack.pack(payload);
    send(nm::CommandAck::kId, payload);
  };
}

void Bridge::send_payload(std::uint32_t msgid, const nm::Payload& payload) {
  const auto frame = writer_->encode(msgid, payload, gate_.outgoing(), signing_now_);
  for (Endpoint* e : endpoints_) e->send(frame);
  ++frames_sent_;
}

ServiceReadiness Bridge::readiness() const {
  const auto& r = inputs_.readiness();
  if (!r) return ServiceReadiness::not_heard;
  return r->ready() ? ServiceReadiness::ready : ServiceReadiness::not_ready;
}

bool Bridge::step(Clock::time_point now) {
  if (signing_clock_) signing_now_ = signing_clock_();
  if (!started_) started_ = now;
  bool alive = true;
  for (Endpoint* e : endpoints_) {
    inbound_.clear();
    alive = e->read_available(inbound_) && alive;
    parser_.push(inbound_.data(), inbound_.size());
    while (auto r = parser_.next()) {
      // Rejections are counted by the parser; a bad frame never stops the program.
      if (const auto* frame = std::get_if<nm::Frame>(&*r)) on_frame(*frame, now);
    }
  }
  inputs_.take();
  // Numbered when first heard, so the parameters and commands know a PMU before its first
  // BATTERY_STATUS; the map's order numbers PMUs heard at once.
  for (const auto& [key, view] : inputs_.pmus()) (void)pmu_slot(key);
  for (const auto& a : inputs_.alarms()) {
    if (a.disposed) {
      alarm_texts_.forget(a.alarm);
    } else if (auto t = alarm_texts_.on_sample(a.alarm)) {
      send(*t);
    }
  }
  if (inputs_.readiness()) {
    if (auto t = readiness_texts_.on_sample(*inputs_.readiness())) send(*t);
  }
  send_due(now);
  return alive;
}

void Bridge::on_frame(const nm::Frame& frame, Clock::time_point now) {
  if (frame.sysid == system_id_ && frame.compid == settings_.component_id) return;  // our own, looped back
  // With a key, a frame addressed to this component that is unsigned, wrongly signed or
  // replayed goes no further: neither this bridge nor the frame handler sees it.
  if (!gate_.admits(frame, system_id_, settings_.component_id, signing_now_)) return;
  if (const auto hb = nm::decode<nm::Heartbeat>(frame)) {
    // The autopilot: a flight controller's HEARTBEAT (not a GCS, not another peripheral).
    // With a key, only a signed one: an unsigned HEARTBEAT from anyone in radio range would
    // otherwise move the component to another system id, away from its ground station.
    if (!system_id_fixed_ && hb->autopilot != nm::mav_autopilot::kInvalid && hb->type != nm::mav_type::kGcs &&
        gate_.authentic(frame, signing_now_)) {
      system_id_fixed_ = true;
      if (frame.sysid != system_id_) {
        system_id_ = frame.sysid;
        writer_ = std::make_unique<nm::FrameWriter>(system_id_, settings_.component_id);
      }
    }
    return;
  }
  if (const auto command = nm::decode<nm::CommandLong>(frame)) {
    const bool to_us = (command->target_system == system_id_ || command->target_system == 0) &&
                       (command->target_component == settings_.component_id || command->target_component == 0);
    if (!to_us) return;
    if (command->command == nm::mav_cmd::kSetMessageInterval || command->command == nm::mav_cmd::kRunPrearmChecks) {
      on_command(frame, *command, now);
      return;
    }
    // A broadcast command is the autopilot's to answer; only one addressed to us is ours.
    if (command->target_component == 0) return;
  }
  other_frames_(frame, sender(), now);
}

void Bridge::on_command(const nm::Frame& frame, const nm::CommandLong& command, Clock::time_point now) {
  nm::CommandAck ack;
  ack.command = command.command;
  ack.target_system = frame.sysid;
  ack.target_component = frame.compid;
  if (command.command == nm::mav_cmd::kSetMessageInterval) {
    ack.result = scheduler_.set_interval(command.param[0], command.param[1], now);
    send(ack);
    return;
  }
  // MAV_CMD_RUN_PREARM_CHECKS: answered, then each reason the service gives as a "PreArm:"
  // line, the form ground stations show for the autopilot's own checks.
  const auto& r = inputs_.readiness();
  if (!r) {
    ack.result = nm::mav_result::kTemporarilyRejected;
    send(ack);
    nm::Statustext t;
    t.severity = nm::mav_severity::kCritical;
    t.text = "PreArm: PMU service not heard";
    send(t);
    return;
  }
  ack.result = nm::mav_result::kAccepted;
  send(ack);
  const auto lines = prearm_lines(*r);
  for (const auto& line : lines) send(line);
  if (lines.empty()) {
    nm::Statustext t;
    t.severity = nm::mav_severity::kInfo;
    t.text = "PMU: pre-arm checks passed";
    send(t);
  }
}

std::uint8_t Bridge::pmu_slot(const DeviceKey& key) {
  const auto it = pmu_slots_.find(key);
  if (it != pmu_slots_.end()) return it->second;
  const auto slot = static_cast<std::uint8_t>(pmu_slots_.size());
  pmu_slots_.emplace(key, slot);
  return slot;
}

std::uint8_t Bridge::bms_slot(const DeviceKey& key) {
  const auto it = bms_slots_.find(key);
  if (it != bms_slots_.end()) return it->second;
  const auto slot = static_cast<std::uint8_t>(bms_slots_.size());
  bms_slots_.emplace(key, slot);
  return slot;
}

void Bridge::send_due(Clock::time_point now) {
  for (const std::uint32_t msgid : scheduler_.due(now)) {
    if (msgid == nm::msgid::kHeartbeat) {
      send(heartbeat(readiness()));
    } else if (msgid == nm::msgid::kBatteryStatus) {
      for (const auto& [key, view] : inputs_.pmus()) {
        const unsigned base = settings_.pmu_battery_id + 2U * pmu_slot(key);
        if (base + 1U > 255U) continue;  // ids run out: more PMUs than the id range holds
        send(pmu_battery_status(view, BatteryInput::a, static_cast<std::uint8_t>(base)));
        send(pmu_battery_status(view, BatteryInput::b, static_cast<std::uint8_t>(base + 1U)));
      }
      for (const auto& [key, view] : inputs_.batteries()) {
        const unsigned id = settings_.bms_battery_id + static_cast<unsigned>(bms_slot(key));
        if (id > 255U) continue;
        send(bms_battery_status(view, static_cast<std::uint8_t>(id)));
      }
    } else if (msgid == nm::msgid::kGeneratorStatus) {
      for (const auto& [key, view] : inputs_.pmus()) send(generator_status(view));
    } else if (msgid == nm::msgid::kRelayStatus) {
      // One message for every PMU, also with none known: silence would leave a ground
      // station showing the outputs' last state (docs/safety.md H7).
      std::vector<std::pair<unsigned, const PmuView*>> numbered;
      for (const auto& [key, view] : inputs_.pmus()) numbered.emplace_back(pmu_slot(key), &view);
      const auto ms = std::chrono::duration_cast<std::chrono::milliseconds>(now - started_.value_or(now)).count();
      send(relay_status(numbered, static_cast<std::uint32_t>(ms)));
    }
  }
}

}  // namespace pmu::mavlink_bridge
