#pragma once
// The parameter and command protocols (interface.md 12.4, 12.5) on the program's loop: the
// bridge's frame handler for PARAM_REQUEST_LIST, PARAM_REQUEST_READ, PARAM_SET and
// COMMAND_LONG, the PMUs' settings from pmu/config into the parameter server, and every
// service request they hand out written to pmu/command, its replies routed back by request
// id (RequestRoutes) to the protocol that asked.
// Lifetime: the bridge, the inputs and the link outlive this. Threads: the loop only.
#include <chrono>
#include <optional>
#include <string>
#include <vector>

#include "pmu/mavlink_commands/command_handler.hpp"
#include "pmu/mavlink_commands/request_routes.hpp"
#include "pmu/mavlink_params/param_server.hpp"
#include "program/bridge.hpp"
#include "program/dds_inputs.hpp"
#include "program/service_link.hpp"

namespace pmu::mavlink_bridge {

class Operations {
 public:
  using Clock = Bridge::Clock;
  // `request_prefix` starts this process's request ids, `first_request` numbers the first
  // (RequestRoutes).
  Operations(const Settings& settings, Bridge& bridge, DdsInputs& inputs, ServiceLink& link, std::string request_prefix,
             std::uint64_t first_request);

  // Bridge::FrameHandler: the frames addressed to this component (or to every component,
  // where MAVLink lets a component answer those) that the protocols take.
  void on_frame(const pmu::mavlink::Frame& frame, const Bridge::Send& send, Clock::time_point now);
  // After each Bridge::step: the PMUs' settings, the service's replies, resends, and what
  // the protocols have due.
  void step(Clock::time_point now);

  // The protocols' counters, one line each, for the program's exit.
  std::vector<std::string> report() const;

 private:
  std::optional<DeviceKey> pmu_key(std::size_t pmu) const;
  void sync_pmus();
  void send_params(const pmu::mavlink_params::Output& out, const Bridge::Send& send, Clock::time_point now);
  void send_commands(const pmu::mavlink_commands::Output& out, const Bridge::Send& send, Clock::time_point now);
  bool addressed_to_us(std::uint8_t system, std::uint8_t component) const;

  Bridge& bridge_;
  DdsInputs& inputs_;
  ServiceLink& link_;
  pmu::mavlink_params::ParamServer params_;
  pmu::mavlink_commands::CommandHandler commands_;
  pmu::mavlink_commands::RequestRoutes routes_;
  std::chrono::milliseconds set_timeout_;
  std::chrono::milliseconds reply_timeout_;
  std::chrono::milliseconds start_timeout_;
  std::vector<std::optional<pmu::baseline::Settings>> known_;  // by PMU: what the server holds
  std::uint64_t not_addressed_ = 0;  // parameter requests and sets for another system or component
};

}  // namespace pmu::mavlink_bridge
