#pragma once
// The program's core: what the endpoints bring in (parsed, counted), what the DDS inputs
// hold, and what goes out when (the rate scheduler). No DDS entity or socket of its own:
// main.cpp owns those and calls step().
// Lifetime: the endpoints and the inputs outlive the Bridge. Threads: one (the loop).
#include <chrono>
#include <cstdint>
#include <functional>
#include <map>
#include <memory>
#include <optional>
#include <vector>

#include "link/endpoint.hpp"
#include "pmu/mavlink/frame.hpp"
#include "pmu/mavlink/parser.hpp"
#include "pmu/mavlink/writer.hpp"
#include "program/dds_inputs.hpp"
#include "program/settings.hpp"
#include "schedule/rate_scheduler.hpp"
#include "signing/signing_gate.hpp"
#include "status/status_texts.hpp"
#include "telemetry/heartbeat.hpp"

namespace pmu::mavlink_bridge {

class Bridge {
 public:
  using Clock = RateScheduler::Clock;

  // What another part of the program answers: a frame the bridge does not handle itself
  // (parameters, and every command but SET_MESSAGE_INTERVAL and RUN_PREARM_CHECKS, which
  // are the bridge's alone) goes here with a function that sends a message's frame on every
  // endpoint. The parameter and command protocols plug in here (program/operations.hpp);
  // without them a COMMAND_LONG addressed to this component gets MAV_RESULT_UNSUPPORTED.
  using Send = std::function<void(std::uint32_t msgid, const pmu::mavlink::Payload& payload)>;
  using FrameHandler = std::function<void(const pmu::mavlink::Frame& frame, const Send& send, Clock::time_point now)>;

  // Message signing (interface.md 12.6): the key, and the clock as a signing timestamp
  // (pmu::mavlink::signing_timestamp of the wall clock), read once per step().
  struct Signing {
    pmu::mavlink::SecretKey key;
    std::function<std::uint64_t()> clock;
  };

  // Without `signing`: nothing signed, every frame taken as it comes.
  Bridge(const Settings& settings, std::vector<Endpoint*> endpoints, DdsInputs& inputs,
         std::optional<Signing> signing = std::nullopt);

  void set_frame_handler(FrameHandler handler) { other_frames_ = std::move(handler); }
  // Sends a message's frame on every endpoint, for what the other parts send unasked.
  Send sender() {
    return [this](std::uint32_t msgid, const pmu::mavlink::Payload& payload) { send_payload(msgid, payload); };
  }

  // Reads every endpoint, takes the DDS samples, says alarm and readiness changes, and sends
  // what the scheduler says is due at `now`. False when an endpoint is gone for good.
  bool step(Clock::time_point now);

  std::uint8_t system_id() const noexcept { return system_id_; }
  std::uint8_t component_id() const noexcept { return settings_.component_id; }
  // Each PMU's number, from 0 in the order first heard (interface.md 12.2): its
  // BATTERY_STATUS ids, and PMU n + 1 of the parameters and commands. Never reused.
  const std::map<DeviceKey, std::uint8_t>& pmu_slots() const noexcept { return pmu_slots_; }
  const pmu::mavlink::ParserCounters& parser_counters() const noexcept { return parser_.counters(); }
  // Frames written since start; each went to every endpoint (their counters say what each
  // could send).
  std::uint64_t frames_sent() const noexcept { return frames_sent_; }
  // Frames signed, accepted and refused by kind; null without signing.
  const pmu::mavlink::SigningCounters* signing_counters() const noexcept { return gate_.counters(); }

 private:
  template <class Message>
  void send(const Message& m) {
    pmu::mavlink::Payload payload{};
    m.pack(payload);
    send_payload(Message::kId, payload);
  }
  void send_payload(std::uint32_t msgid, const pmu::mavlink::Payload& payload);
  void on_frame(const pmu::mavlink::Frame& frame, Clock::time_point now);
  void on_command(const pmu::mavlink::Frame& frame, const pmu::mavlink::CommandLong& command, Clock::time_point now);
  void send_due(Clock::time_point now);
  std::uint8_t pmu_slot(const DeviceKey& key);
  std::uint8_t bms_slot(const DeviceKey& key);
  ServiceReadiness readiness() const;

  const Settings& settings_;
  std::vector<Endpoint*> endpoints_;
  DdsInputs& inputs_;
  std::uint8_t system_id_;
  bool system_id_fixed_;
  pmu::mavlink::Parser parser_;
  std::unique_ptr<pmu::mavlink::FrameWriter> writer_;
  RateScheduler scheduler_;
  AlarmTexts alarm_texts_;
  ReadinessTexts readiness_texts_;
  std::map<DeviceKey, std::uint8_t> pmu_slots_;
  std::map<DeviceKey, std::uint8_t> bms_slots_;
  FrameHandler other_frames_;
  SigningGate gate_;
  std::function<std::uint64_t()> signing_clock_;
  std::uint64_t signing_now_ = 0;
  std::uint64_t frames_sent_ = 0;
  std::optional<Clock::time_point> started_;  // the first step: RELAY_STATUS's time_boot_ms counts from it
  std::vector<std::uint8_t> inbound_;
};

}  // namespace pmu::mavlink_bridge
