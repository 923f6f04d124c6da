#include "pmuctl/call/command_channel.hpp"

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <fastdds/dds/core/status/PublicationMatchedStatus.hpp>
#include <fastdds/dds/core/status/SubscriptionMatchedStatus.hpp>
#include <fastdds/dds/subscriber/SampleInfo.hpp>
#include <map>
#include <set>
#include <thread>

#include "pmu/command/command.hpp"
#include "pmu/idl/commandPubSubTypes.h"
#include "pmu/idl/guarded_type.hpp"
#include "pmu/idl/state.h"
#include "pmu/idl/statePubSubTypes.h"
#include "pmu/idl/topics.hpp"
#include "pmuctl/call/exit_status.hpp"
#include "pmuctl/call/service_presence.hpp"
#include "pmuctl/call/target_search.hpp"

namespace pmu::tools {
namespace {
using namespace eprosima::fastdds::dds;
using Clock = std::chrono::steady_clock;
}  // namespace

// Finds the PMU the command is for: --bus/--address when both are given, else the only PMU
// (Health.kind: batteries and MPPTs take no commands) the service of `vehicle` knows.
// nullopt when found; else the exit status, after saying why in words a person can act on.
// The vehicle is never guessed: a command names --vehicle, or goes to the unnamed vehicle.
std::optional<int> resolve_target(const GlobalOptions& o, const std::string& vehicle, pmu::dds::DdsContext& dds,
                                  Clock::time_point deadline, std::string& bus, std::uint16_t& address) {
  if (!o.bus.empty() && o.address) {
    bus = o.bus;
    address = *o.address;
    return std::nullopt;
  }
  DataReader& r = dds.reader(dds.topic(topics::kHealth, TypeSupport(new idl::Guarded<pmu::v5::HealthPubSubType>())),
                             qos_profiles::kState);
  std::set<std::string> vehicles_seen;
  bool own_vehicle_seen = false;
  std::map<InstanceHandle_t, TargetSearch::Pmu> handles;
  // The disposal of a moved PMU's old key follows its OFFLINE sample by 250 ms at the service
  // (target_search.hpp); a second is ample for it to cross a slow link behind that sample.
  TargetSearch search(std::chrono::milliseconds(300), std::chrono::seconds(1));
  bool heard = false;
  while (Clock::now() < deadline) {
    pmu::v5::Health h;
    SampleInfo info;
    while (r.take_next_sample(&h, &info) == ReturnCode_t::RETCODE_OK) {
      heard = true;
      if (!info.valid_data) {
        // Disposed: a PMU that moved to another address is not a second PMU.
        if (auto it = handles.find(info.instance_handle);
            it != handles.end() && info.instance_state != ALIVE_INSTANCE_STATE)
          search.gone(it->second);
        continue;
      }
      vehicles_seen.insert(h.vehicle().to_string());
      own_vehicle_seen = own_vehicle_seen || h.vehicle().to_string() == vehicle;
      if (h.kind() == pmu::v5::KIND_PMU && h.vehicle().to_string() == vehicle &&
          (o.bus.empty() || o.bus == h.bus().to_string()) && (!o.address || *o.address == h.address())) {
        const TargetSearch::Pmu pmu{h.bus().to_string(), h.address()};
        search.seen(pmu, h.state() == pmu::v5::OFFLINE, Clock::now());
        handles[info.instance_handle] = pmu;
      }
    }
    // The service's health is TRANSIENT_LOCAL: all of it comes in one burst once matched, so
    // the settle time starts with its first sample, of the wanted PMU or not. Other
    // vehicles' samples do not start it: on a slow link their services are discovered one
    // by one, and the one asked for may still come.
    if (!search.pmus().empty() || own_vehicle_seen) search.start(Clock::now());
    if (search.settled(Clock::now())) break;
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  const std::set<TargetSearch::Pmu> seen = search.pmus();
  SubscriptionMatchedStatus st;
  r.get_subscription_matched_status(st);
  if (st.current_count == 0) return no_service(o, dds);
  if (!heard) return nothing_heard(o);
  if (seen.empty() && !vehicles_seen.count(vehicle))
    return fail(o, ExitStatus::BadUsage,
                "no pmu-service of " + vehicle_text(vehicle) + " on domain " + std::to_string(o.domain) +
                    vehicles_seen_text(vehicles_seen));
  const std::string on_bus = o.bus.empty() ? std::string() : " on " + o.bus;
  if (seen.empty())
    return fail(o, ExitStatus::BadUsage,
                o.address ? "PMU " + std::to_string(*o.address) + " not seen" + on_bus
                          : "the service knows no PMU" + on_bus);
  if (seen.size() > 1) {
    std::string list;
    for (const auto& [b, a] : seen) list += (list.empty() ? "" : ", ") + b + "/" + std::to_string(a);
    return fail(o, ExitStatus::BadUsage, "several PMUs (" + list + "): choose one with --bus and --address");
  }
  bus = seen.begin()->first;
  address = seen.begin()->second;
  return std::nullopt;
}

// Waits until the service's request reader and reply writer are matched: a request written
// before would be lost, a reply sent before would never be seen. nullopt when matched.
std::optional<int> wait_for_match(const GlobalOptions& o, pmu::dds::DdsContext& dds, DataWriter& writer,
                                  DataReader& replies, const std::string& vehicle, Clock::time_point deadline,
                                  const char* accepts) {
  for (;;) {
    PublicationMatchedStatus pub;
    SubscriptionMatchedStatus sub;
    writer.get_publication_matched_status(pub);
    replies.get_subscription_matched_status(sub);
    if (pub.current_count > 0 && sub.current_count > 0) return std::nullopt;
    if (Clock::now() >= deadline) {
      if (pub.current_count == 0 && sub.current_count == 0) return no_service(o, dds);
      return fail(o, ExitStatus::NoAnswer,
                  "no pmu-service of " + vehicle_text(vehicle) + " on domain " + std::to_string(o.domain) + " " +
                      accepts + vehicles_seen_text(vehicles_on_domain(dds)));
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
}

CommandChannel::CommandChannel(const GlobalOptions& o)
    : options_(o),
      vehicle_(o.vehicle.value_or(std::string())),
      lease_(o, kPmuctlParticipant),
      dds_(*lease_),
      replies_(dds_.reader(
          dds_.topic(topics::kCommandReply, TypeSupport(new idl::Guarded<pmu::v5::CommandReplyPubSubType>())),
          qos_profiles::kCommand)),
      writer_(dds_.writer(dds_.topic(topics::kCommand, TypeSupport(new pmu::v5::CommandPubSubType())),
                          qos_profiles::kCommand)) {}

void open_command_channels(const GlobalOptions& o, const std::vector<std::string>& vehicles) {
  if (!o.pool || o.pool->commands_refused()) return;
  for (const auto& vehicle : vehicles) {
    GlobalOptions one = o;
    one.vehicle = vehicle;
    try {
      const CommandChannel channel(one);  // its lease parks the endpoints, matched
    } catch (const pmu::dds::DdsError&) {
      o.pool->refuse_commands();  // tried once: each try would have Fast DDS log its refusal
      return;
    }
  }
}

std::optional<int> CommandChannel::open(Clock::time_point deadline, std::string& bus, std::uint16_t& address,
                                        Find find) {
  recalled_ = false;
  if (find != Find::Broadcast) {
    TargetMemory* memory = options_.pool ? &options_.pool->targets() : nullptr;
    const bool named = !options_.bus.empty() && options_.address;  // nothing to find
    if (memory && find == Find::MayRecall && !named)
      if (const auto t = memory->recall(query(), Clock::now())) {
        bus = t->bus;
        address = t->address;
        recalled_ = true;
      }
    if (!recalled_) {
      if (const auto failed = resolve_target(options_, vehicle_, dds_, deadline, bus, address)) return failed;
      if (memory && !named) memory->remember(query(), {bus, address}, Clock::now());
    }
  }
  return wait_for_match(options_, dds_, writer_, replies_, vehicle_, deadline, "accepts commands");
}

bool CommandChannel::recalled_target_gone(const Outcome& out, const std::string& bus, std::uint16_t address) {
  if (!recalled_ || !options_.pool || !out.reply || out.reply->result() != pmu::v5::REJECTED ||
      !says_target_gone(out.reply->reason().to_string(), {bus, address}))
    return false;
  options_.pool->targets().forget(query());
  recalled_ = false;
  return true;
}

CommandChannel::Outcome CommandChannel::send(const CommandSpec& spec, const std::string& bus, std::uint16_t address,
                                             double timeout, std::uint64_t expires_at_ns) {
  const auto deadline =
      Clock::now() + std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(timeout));
  pmu::v5::Command c;
  Outcome out;
  out.request_id = spec.request_id.empty() ? request_id() : spec.request_id;
  c.request_id(out.request_id);
  c.vehicle(vehicle_);
  c.bus(bus);
  c.address(address);
  c.kind(static_cast<pmu::v5::CommandKind>(spec.kind));
  c.parameter(spec.parameter);
  c.value(spec.value);
  c.outputs(spec.outputs);
  c.enable(spec.enable);
  c.groups(spec.groups);
  c.expires_at(expires_at_ns ? expires_at_ns : epoch_ns_at(deadline));
  c.confirm(spec.confirm);
  if (!writer_.write(&c)) {  // bool in Fast DDS 2.x
    out.written = false;
    return out;
  }

  // A request that met no reply is sent again with the same id (interface.md 2.4: answered
  // again, never executed twice): a reader that matched a moment too late, or a service that
  // had not yet seen this writer in discovery (section 5), answers the resend.
  constexpr auto kResendAfter = std::chrono::seconds(1);
  auto next_resend = Clock::now() + kResendAfter;
  bool heard = false;
  // A long command (an engine start, which is verified for up to CT + 2 s) reports progress
  // at least once a second: each report keeps the wait open a little longer than that, so
  // the timeout bounds the wait for the service, not the engine.
  constexpr auto kProgressKeepsOpen = std::chrono::seconds(3);
  auto wait_until = deadline + std::chrono::milliseconds(500);
  while (Clock::now() < wait_until) {
    if (!heard && Clock::now() >= next_resend && Clock::now() < deadline) {
      (void)writer_.write(&c);
      next_resend = Clock::now() + kResendAfter;
    }
    pmu::v5::CommandReply r;
    SampleInfo info;
    while (replies_.take_next_sample(&r, &info) == ReturnCode_t::RETCODE_OK) {
      if (!info.valid_data || r.request_id().to_string() != out.request_id || r.vehicle().to_string() != vehicle_)
        continue;
      heard = true;
      if (r.result() == pmu::v5::IN_PROGRESS) {
        std::fprintf(stderr, "IN_PROGRESS: %s\n", r.reason().c_str());
        wait_until = std::max(wait_until, Clock::now() + kProgressKeepsOpen);
        continue;
      }
      out.reply = r;
      return out;
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  }
  return out;
}

}  // namespace pmu::tools
