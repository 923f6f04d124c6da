#include "pmuctl/verbs/command_verbs.hpp"

#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <fastdds/dds/core/status/PublicationMatchedStatus.hpp>
#include <fastdds/dds/core/status/SubscriptionMatchedStatus.hpp>
#include <fastdds/dds/subscriber/SampleInfo.hpp>
#include <map>
#include <optional>
#include <set>
#include <thread>
#include <vector>

#include "pmu/codec/ids.hpp"
#include "pmu/codec/messages.hpp"
#include "pmu/command/command.hpp"
#include "pmu/dds/dds_context.hpp"
#include "pmu/idl/alarms.h"
#include "pmu/idl/alarmsPubSubTypes.h"
#include "pmu/idl/command.h"
#include "pmu/idl/commandPubSubTypes.h"
#include "pmu/idl/guarded_type.hpp"
#include "pmu/idl/state.h"
#include "pmu/idl/statePubSubTypes.h"
#include "pmu/idl/topics.hpp"
#include "pmuctl/verbs/alarm_names.hpp"
#include "pmuctl/verbs/exit_status.hpp"
#include "pmuctl/verbs/service_presence.hpp"
#include "pmuctl/view/sample_json.hpp"

namespace pmu::tools {
namespace {

using namespace eprosima::fastdds::dds;
using Clock = std::chrono::steady_clock;

// The service's names for its results; pmu::v4::CommandResult has the same order (static_assert
// in dds/src/dds_commands.cpp). The names are literals, so data() ends in NUL.
const char* result_name(pmu::v4::CommandResult r) {
  return pmu::service::to_string(static_cast<pmu::service::CommandResult>(r)).data();
}

std::string request_id() {
  char host[64] = "host";
  ::gethostname(host, sizeof host - 1);
  const auto ns = std::chrono::duration_cast<std::chrono::nanoseconds>(
                      std::chrono::system_clock::now().time_since_epoch())
                      .count();
  return "pmuctl-" + std::string(host).substr(0, 24) + "-" + std::to_string(::getpid()) + "-" + std::to_string(ns);
}

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
  DataReader& r = dds.reader(dds.topic(topics::kHealth, TypeSupport(new idl::Guarded<pmu::v4::HealthPubSubType>())),
                             qos_profiles::kState);
  std::set<std::pair<std::string, std::uint16_t>> seen;
  std::set<std::string> vehicles_seen;
  bool own_vehicle_seen = false;
  std::map<InstanceHandle_t, std::pair<std::string, std::uint16_t>> handles;
  std::optional<Clock::time_point> settle;
  while (Clock::now() < deadline) {
    pmu::v4::Health h;
    SampleInfo info;
    while (r.take_next_sample(&h, &info) == ReturnCode_t::RETCODE_OK) {
      if (!info.valid_data) {
        // Disposed: a PMU that moved to another address is not a second PMU.
        if (auto it = handles.find(info.instance_handle); it != handles.end() && info.instance_state != ALIVE_INSTANCE_STATE)
          seen.erase(it->second);
        continue;
      }
      vehicles_seen.insert(h.vehicle().to_string());
      own_vehicle_seen = own_vehicle_seen || h.vehicle().to_string() == vehicle;
      if (h.kind() == pmu::v4::KIND_PMU && h.vehicle().to_string() == vehicle &&
          (o.bus.empty() || o.bus == h.bus().to_string()) && (!o.address || *o.address == h.address())) {
        seen.insert({h.bus().to_string(), h.address()});
        handles[info.instance_handle] = {h.bus().to_string(), h.address()};
      }
    }
    // The service's health is TRANSIENT_LOCAL: all of it comes in one burst once matched, so
    // the settle time starts with its first sample, of the wanted PMU or not. Other
    // vehicles' samples do not start it: on a slow link their services are discovered one
    // by one, and the one asked for may still come.
    if ((!seen.empty() || own_vehicle_seen) && !settle) settle = Clock::now() + std::chrono::milliseconds(300);
    if (settle && Clock::now() >= *settle) break;
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  SubscriptionMatchedStatus st;
  r.get_subscription_matched_status(st);
  if (st.current_count == 0) return no_service(o, dds);
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

std::uint64_t epoch_ns_after(double seconds) {
  const auto t = std::chrono::system_clock::now() +
                 std::chrono::duration_cast<std::chrono::system_clock::duration>(std::chrono::duration<double>(seconds));
  return static_cast<std::uint64_t>(std::chrono::duration_cast<std::chrono::nanoseconds>(t.time_since_epoch()).count());
}

}  // namespace

int run_alarm_ack(const GlobalOptions& o, const std::string& code, const std::string& kind) {
  const double timeout = o.timeout.value_or(5.0);
  const auto deadline = Clock::now() + std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(timeout));
  const std::string vehicle = o.vehicle.value_or(std::string());
  pmu::v4::AlarmSource source = pmu::v4::SOURCE_PMU;
  if (kind == "battery")
    source = pmu::v4::SOURCE_BATTERY;
  else if (kind == "mppt")
    source = pmu::v4::SOURCE_MPPT;
  else if (kind == "bus")
    source = pmu::v4::SOURCE_BUS;
  else if (kind != "pmu")
    return fail(o, ExitStatus::BadUsage, "--kind '" + pmu::service::printable(kind) + "': pmu, battery, mppt or bus");
  if (source == pmu::v4::SOURCE_BUS && o.bus.empty())
    return fail(o, ExitStatus::BadUsage, "a bus alarm needs --bus");
  if ((source == pmu::v4::SOURCE_BATTERY || source == pmu::v4::SOURCE_MPPT) && (o.bus.empty() || !o.address))
    return fail(o, ExitStatus::BadUsage, "a " + kind + " alarm needs --bus and --address (the " +
                                             (source == pmu::v4::SOURCE_BATTERY ? "CANopen node" : "MPPT device id") +
                                             ")");
  pmu::dds::DdsContext dds(o.domain, o.qos_file, "pmuctl", o.security, pmu::dds::Transport::Default, o.network,
                           partitions_for(o));
  DataReader& replies = dds.reader(
      dds.topic(topics::kAlarmAckReply, TypeSupport(new idl::Guarded<pmu::v4::AlarmAckReplyPubSubType>())),
      qos_profiles::kCommand);
  DataWriter& writer =
      dds.writer(dds.topic(topics::kAlarmAck, TypeSupport(new pmu::v4::AlarmAckPubSubType())), qos_profiles::kCommand);
  std::string bus = o.bus;
  std::uint16_t device = source == pmu::v4::SOURCE_BUS ? 0 : o.address.value_or(0);
  if (source == pmu::v4::SOURCE_PMU)
    if (const auto failed = resolve_target(o, vehicle, dds, deadline, bus, device)) return *failed;
  if (const auto failed = wait_for_match(o, dds, writer, replies, vehicle, deadline, "accepts alarm acknowledgements"))
    return *failed;

  pmu::v4::AlarmAck a;
  const std::string id = request_id();
  a.request_id(id);
  a.vehicle(vehicle);
  a.bus(bus);
  a.kind(source);
  a.device(device);
  a.code(code);
  a.expires_at(epoch_ns_after(timeout));
  if (!writer.write(&a)) return fail(o, ExitStatus::NotDone, "the acknowledgement could not be written to DDS");

  // Unanswered after 1 s: sent again with the same id, which the service answers again and
  // never applies twice (interface.md 2.4, and 1.6 for acknowledgements).
  constexpr auto kResendAfter = std::chrono::seconds(1);
  auto next_resend = Clock::now() + kResendAfter;
  const auto wait_until = deadline + std::chrono::milliseconds(500);
  while (Clock::now() < wait_until) {
    if (Clock::now() >= next_resend && Clock::now() < deadline) {
      (void)writer.write(&a);
      next_resend = Clock::now() + kResendAfter;
    }
    pmu::v4::AlarmAckReply r;
    SampleInfo info;
    while (replies.take_next_sample(&r, &info) == ReturnCode_t::RETCODE_OK) {
      if (!info.valid_data || r.request_id().to_string() != id || r.vehicle().to_string() != vehicle) continue;
      const bool done = r.result() == pmu::v4::ACK_COMPLETED;
      const char* result = done ? "COMPLETED" : "REJECTED";
      if (o.json) {
        Json j{{"request_id", id},
               {"vehicle", r.vehicle().to_string()},
               {"bus", r.bus().to_string()},
               {"kind", kind},
               {"device", r.device()},
               {"code", r.code().to_string()},
               {"result", result},
               {"reason", r.reason().to_string()},
               {"state", alarm_state_name(r.state())}};
        std::printf("%s\n", j.dump(-1, ' ', false, nlohmann::json::error_handler_t::replace).c_str());
      }
      std::fprintf(stderr, "%s: %s (now %s)\n", result, r.reason().c_str(), alarm_state_name(r.state()));
      return static_cast<int>(done ? ExitStatus::Ok : ExitStatus::NotDone);
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  }
  char waited[96];
  std::snprintf(waited, sizeof waited, "no reply from pmu-service within %.1f s (request ", timeout);
  const std::string message = waited + id + ")";
  std::fprintf(stderr, "pmuctl: %s\n", message.c_str());
  if (o.json) {
    Json j{{"request_id", id}, {"vehicle", vehicle}, {"bus", bus}, {"kind", kind}, {"device", device},
           {"code", code},     {"result", nullptr},  {"reason", message},
           {"exit_status", static_cast<int>(ExitStatus::NoAnswer)}};
    std::printf("%s\n", j.dump(-1, ' ', false, nlohmann::json::error_handler_t::replace).c_str());
  }
  return static_cast<int>(ExitStatus::NoAnswer);
}

bool output_mask(const std::vector<std::string>& names, std::uint8_t& mask) {
  mask = 0;
  for (const auto& n : names) {
    if (n == "none") continue;
    if (n == "all") {
      mask = codec::output_bit::All;
      continue;
    }
    const auto bit = codec::bit_named(codec::kOutputNames, n);
    if (!bit) {
      std::fprintf(stderr, "pmuctl: unknown output '%s' (outputs: %s)\n", n.c_str(),
                   codec::names_of(codec::kOutputNames, codec::output_bit::All, ", ").c_str());
      return false;
    }
    mask = static_cast<std::uint8_t>(mask | *bit);
  }
  return true;
}

bool group_mask(const std::vector<std::string>& names, std::uint8_t& mask) {
  mask = 0;
  for (const auto& n : names) {
    const auto bit = codec::bit_named(codec::kGroupNames, n);
    if (!bit) {
      std::fprintf(stderr, "pmuctl: unknown measurement group '%s' (%s)\n", n.c_str(),
                   codec::names_of(codec::kGroupNames, codec::group_bit::All, ", ").c_str());
      return false;
    }
    mask = static_cast<std::uint8_t>(mask | *bit);
  }
  return true;
}

std::string broadcast_refusal(const GlobalOptions& o, int kind) {
  if (!o.address || *o.address != codec::kBroadcastAddress || kind == pmu::v4::ENGINE_STOP) return {};
  return "--address 65535 (broadcast) is only for `engine stop`: every other command names one PMU";
}

int run_command(const GlobalOptions& o, const CommandSpec& spec) {
  const double timeout = o.timeout.value_or(5.0);
  const auto deadline = Clock::now() + std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(timeout));
  const std::string vehicle = o.vehicle.value_or(std::string());
  // Reading every vehicle's health (without --vehicle) lets a failure name the vehicles there are.
  pmu::dds::DdsContext dds(o.domain, o.qos_file, "pmuctl", o.security, pmu::dds::Transport::Default, o.network,
                           partitions_for(o));
  DataReader& replies = dds.reader(dds.topic(topics::kCommandReply, TypeSupport(new idl::Guarded<pmu::v4::CommandReplyPubSubType>())),
                                   qos_profiles::kCommand);
  DataWriter& writer =
      dds.writer(dds.topic(topics::kCommand, TypeSupport(new pmu::v4::CommandPubSubType())), qos_profiles::kCommand);

  // A stop to the broadcast address needs no PMU seen: with --bus it goes to that bus, without
  // to every bus of the service (bus ""), so an engine can be stopped whatever the service
  // has read so far.
  const bool broadcast = spec.kind == pmu::v4::ENGINE_STOP && o.address && *o.address == codec::kBroadcastAddress;
  std::string bus = broadcast ? o.bus : std::string();
  std::uint16_t address = broadcast ? codec::kBroadcastAddress : 0;
  if (!broadcast)
    if (const auto failed = resolve_target(o, vehicle, dds, deadline, bus, address)) return *failed;

  if (const auto failed = wait_for_match(o, dds, writer, replies, vehicle, deadline, "accepts commands"))
    return *failed;

  pmu::v4::Command c;
  const std::string id = request_id();
  c.request_id(id);
  c.vehicle(vehicle);
  c.bus(bus);
  c.address(address);
  c.kind(static_cast<pmu::v4::CommandKind>(spec.kind));
  c.parameter(spec.parameter);
  c.value(spec.value);
  c.outputs(spec.outputs);
  c.enable(spec.enable);
  c.groups(spec.groups);
  const auto expires = std::chrono::system_clock::now() + std::chrono::duration_cast<std::chrono::system_clock::duration>(
                                                              std::chrono::duration<double>(timeout));
  c.expires_at(static_cast<std::uint64_t>(
      std::chrono::duration_cast<std::chrono::nanoseconds>(expires.time_since_epoch()).count()));
  c.confirm(spec.confirm);
  if (!writer.write(&c))  // bool in Fast DDS 2.x
    return fail(o, ExitStatus::NotDone, "the command could not be written to DDS");

  // A request that met no reply is sent again with the same id (interface.md 2.4: answered
  // again, never executed twice): a reader that matched a moment too late, or a service that
  // had not yet seen this writer in discovery (section 5), answers the resend.
  constexpr auto kResendAfter = std::chrono::seconds(1);
  auto next_resend = Clock::now() + kResendAfter;
  bool heard = false;
  // A long command (an engine start, which is verified for up to CT + 2 s) reports progress
  // at least once a second: each report keeps the wait open a little longer than that, so
  // --timeout bounds the wait for the service, not the engine.
  constexpr auto kProgressKeepsOpen = std::chrono::seconds(3);
  auto wait_until = deadline + std::chrono::milliseconds(500);
  while (Clock::now() < wait_until) {
    if (!heard && Clock::now() >= next_resend && Clock::now() < deadline) {
      (void)writer.write(&c);
      next_resend = Clock::now() + kResendAfter;
    }
    pmu::v4::CommandReply r;
    SampleInfo info;
    while (replies.take_next_sample(&r, &info) == ReturnCode_t::RETCODE_OK) {
      if (!info.valid_data || r.request_id().to_string() != id || r.vehicle().to_string() != vehicle) continue;
      heard = true;
      if (r.result() == pmu::v4::IN_PROGRESS) {
        std::fprintf(stderr, "IN_PROGRESS: %s\n", r.reason().c_str());
        wait_until = std::max(wait_until, Clock::now() + kProgressKeepsOpen);
        continue;
      }
      if (o.json) {
        Json j{{"request_id", id},
               {"vehicle", r.vehicle().to_string()},
               {"bus", r.bus().to_string()},
               {"address", r.address()},
               {"result", result_name(r.result())},
               {"reason", r.reason().to_string()}};
        if (r.has_value()) j["value"] = r.value();
        if (!(r.value_text().size() == 0)) j["value_text"] = r.value_text().to_string();
        std::printf("%s\n", j.dump(-1, ' ', false, nlohmann::json::error_handler_t::replace).c_str());
      } else if (r.has_value() || !(r.value_text().size() == 0)) {
        if (!(r.value_text().size() == 0))
          std::printf("%s\n", r.value_text().c_str());
        else
          std::printf("%g\n", r.value());
      }
      std::fprintf(stderr, "%s%s%s\n", result_name(r.result()), (r.reason().size() == 0) ? "" : ": ", r.reason().c_str());
      return static_cast<int>(r.result() == pmu::v4::COMPLETED ? ExitStatus::Ok : ExitStatus::NotDone);
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  }
  char waited[96];
  std::snprintf(waited, sizeof waited, "no reply from pmu-service within %.1f s (request ", timeout);
  const std::string message = waited + id + ")";
  std::fprintf(stderr, "pmuctl: %s\n", message.c_str());
  if (o.json) {
    // The line of a reply that never came: the same keys, a null result.
    Json j{{"request_id", id},     {"vehicle", vehicle},  {"bus", bus},
           {"address", address},   {"result", nullptr},   {"reason", message},
           {"exit_status", static_cast<int>(ExitStatus::NoAnswer)}};
    std::printf("%s\n", j.dump(-1, ' ', false, nlohmann::json::error_handler_t::replace).c_str());
  }
  return static_cast<int>(ExitStatus::NoAnswer);
}

}  // namespace pmu::tools
