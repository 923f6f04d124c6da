#include "program/operations.hpp"

#include <cstdio>

#include "pmu/mavlink/messages.hpp"

namespace pmu::mavlink_bridge {

namespace nm = pmu::mavlink;
namespace mp = pmu::mavlink_params;
namespace mc = pmu::mavlink_commands;

namespace {

// A request's expires_at: the service's default lifetime (interface.md 2.3), within which its
// first frame goes out; the owners wait a little longer for the final reply (their timeouts).
constexpr std::chrono::seconds kRequestLifetime{10};

mp::ParamServerConfig operations_param_config(const Settings& s) {
  mp::ParamServerConfig c;
  c.pmu_count = 1;  // grows as PMUs are heard
  c.confirm = s.confirm;
  return c;
}

mc::CommandConfig operations_command_config(const Settings& s) {
  mc::CommandConfig c;
  // Every number a PMU can have; one not heard (yet) is answered by the program.
  c.pmu_count = mp::kMaxPmus;
  c.confirm = s.confirm;
  c.own_component = s.component_id;
  return c;
}

template <class Message>
void send_message(const Bridge::Send& send, const Message& m) {
  nm::Payload payload{};
  m.pack(payload);
  send(Message::kId, payload);
}

}  // namespace

Operations::Operations(const Settings& settings, Bridge& bridge, DdsInputs& inputs, ServiceLink& link,
                       std::string request_prefix, std::uint64_t first_request)
    : bridge_(bridge),
      inputs_(inputs),
      link_(link),
      params_(operations_param_config(settings)),
      commands_(operations_command_config(settings)),
      routes_(std::move(request_prefix), first_request),
      set_timeout_(operations_param_config(settings).set_timeout),
      reply_timeout_(operations_command_config(settings).reply_timeout),
      start_timeout_(operations_command_config(settings).start_timeout) {}

bool Operations::addressed_to_us(std::uint8_t system, std::uint8_t component) const {
  // The devguide's parameter service: a component answers requests to its id and to
  // MAV_COMP_ID_ALL (QGroundControl asks every component of the system with 0).
  return (system == bridge_.system_id() || system == 0) && (component == bridge_.component_id() || component == 0);
}

std::optional<DeviceKey> Operations::pmu_key(std::size_t pmu) const {
  for (const auto& [key, slot] : bridge_.pmu_slots())
    if (slot == pmu) return key;
  return std::nullopt;
}

void Operations::on_frame(const nm::Frame& frame, const Bridge::Send& send, Clock::time_point now) {
  const mp::Sender from{frame.sysid, frame.compid};
  if (const auto list = nm::decode<nm::ParamRequestList>(frame)) {
    if (!addressed_to_us(list->target_system, list->target_component)) return void(++not_addressed_);
    params_.on_request_list(from, now);
  } else if (const auto read = nm::decode<nm::ParamRequestRead>(frame)) {
    if (!addressed_to_us(read->target_system, read->target_component)) return void(++not_addressed_);
    params_.on_request_read(from, *read, now);
  } else if (const auto set = nm::decode<nm::ParamSet>(frame)) {
    if (!addressed_to_us(set->target_system, set->target_component)) return void(++not_addressed_);
    send_params(params_.on_param_set(from, *set, now), send, now);
  } else if (const auto command = nm::decode<nm::CommandLong>(frame)) {
    // The bridge passes on only commands addressed to this component (a broadcast command
    // is the autopilot's to answer), SET_MESSAGE_INTERVAL and RUN_PREARM_CHECKS aside.
    send_commands(commands_.on_command_long(from, *command, now), send, now);
  }
}

void Operations::send_params(const mp::Output& out, const Bridge::Send& send, Clock::time_point now) {
  for (const auto& m : out.send) std::visit([&](const auto& message) { send_message(send, message); }, m);
  if (!out.request) return;
  const auto& r = *out.request;
  const auto key = pmu_key(r.param.pmu);
  if (!key) {  // a PMU whose values are known was heard: not reached, but never left unanswered
    send_params(params_.on_set_reply(r.tag, service::CommandResult::Rejected, "PMU not heard"), send, now);
    return;
  }
  const auto id = routes_.open({mc::Owner::Params, r.tag}, now + kRequestLifetime, now + set_timeout_, now);
  link_.send(id, r.action(), std::get<0>(*key), std::get<1>(*key), r.confirm, now + kRequestLifetime);
}

void Operations::send_commands(const mc::Output& out, const Bridge::Send& send, Clock::time_point now) {
  for (const auto& a : out.acks) send_message(send, a);
  for (const auto& t : out.texts) send_message(send, t);
  if (!out.command) return;
  const auto& c = *out.command;
  const auto key = pmu_key(c.pmu);
  if (!key) {
    send_commands(commands_.on_reply(c.tag, service::CommandResult::Rejected,
                                     "PMU" + std::to_string(c.pmu + 1) + " not heard by pmu-mavlink", now),
                  send, now);
    return;
  }
  const bool start = std::holds_alternative<service::action::EngineStart>(c.action);
  const auto id = routes_.open({mc::Owner::Commands, c.tag}, now + kRequestLifetime,
                               now + (start ? start_timeout_ : reply_timeout_), now);
  link_.send(id, c.action, std::get<0>(*key), std::get<1>(*key), c.confirm, now + kRequestLifetime);
}

void Operations::sync_pmus() {
  for (const auto& [key, slot] : bridge_.pmu_slots()) {
    if (slot >= mp::kMaxPmus) continue;  // beyond PMU9: no parameters, no commands
    params_.grow(std::size_t{slot} + 1U);
    if (known_.size() <= slot) known_.resize(std::size_t{slot} + 1U);
    // Known while the PMU is ONLINE and its pmu/config instance lives (docs/safety.md H7).
    const auto view = inputs_.pmus().find(key);
    const auto config = inputs_.configs().find(key);
    std::optional<baseline::Settings> now_known;
    if (view != inputs_.pmus().end() && view->second.online && config != inputs_.configs().end())
      now_known = config->second;
    auto& held = known_[slot];
    if (now_known.has_value() == held.has_value() && (!now_known || now_known->raw == held->raw)) continue;
    if (now_known)
      params_.set_device(slot, *now_known);
    else
      params_.forget_device(slot);
    held = now_known;
  }
}

void Operations::step(Clock::time_point now) {
  const auto send = bridge_.sender();
  sync_pmus();
  for (const auto& reply : link_.take()) {
    const bool final = service::is_final(reply.result);
    const auto route = routes_.on_reply(reply.request_id, final);
    if (!route) continue;
    if (final) link_.forget(reply.request_id);
    if (route->owner == mc::Owner::Params)
      send_params(params_.on_set_reply(route->tag, reply.result, reply.reason), send, now);
    else
      send_commands(commands_.on_reply(route->tag, reply.result, reply.reason, now), send, now);
  }
  for (const auto& id : routes_.due(now)) link_.write_again(id);
  send_params(params_.poll(now), send, now);
  send_commands(commands_.poll(now), send, now);
}

std::vector<std::string> Operations::report() const {
  const auto n = [](std::uint64_t v) { return std::to_string(v); };
  const auto& p = params_.counters();
  const auto& c = commands_.counters();
  const auto& r = routes_.counters();
  const auto& l = link_.counters();
  return {
      "parameters: list requests " + n(p.list_requests) + " (merged " + n(p.list_requests_merged) + "), reads " +
          n(p.reads) + " (unanswered " + n(p.reads_unanswered) + "), values sent " + n(p.values_sent) + ", sets " +
          n(p.sets) + " (sent " + n(p.sets_sent) + ", merged " + n(p.sets_merged) + ", refused " + n(p.sets_refused) +
          ", unknown name " + n(p.sets_unknown_name) + ", timed out " + n(p.sets_timed_out) +
          "), not addressed to us " + n(not_addressed_),
      "commands: received " + n(c.received) + ", retransmissions " + n(c.retransmissions) + ", sent " + n(c.sent) +
          " (stops " + n(c.stops) + "), denied " + n(c.denied) + ", unsupported " + n(c.unsupported) +
          ", flood rejected " + n(c.flood_rejected) + ", timed out " + n(c.timed_out),
      "service requests: written " + n(l.written) + " (resends " + n(r.resends) + ", write failures " +
          n(l.write_failures) + "), replies routed " + n(r.replies_routed) + ", unknown request id " +
          n(r.replies_unknown) + ", late " + n(p.replies_unmatched + c.replies_unmatched) + ", other clients' " +
          n(r.replies_others) + ", other vehicles' " + n(l.other_vehicles),
  };
}

}  // namespace pmu::mavlink_bridge
