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
#include "pmuctl/call/command_channel.hpp"
#include "pmuctl/call/exit_status.hpp"
#include "pmuctl/call/service_presence.hpp"
#include "pmuctl/view/sample_json.hpp"
#include "pmuctl/call/context_lease.hpp"

namespace pmu::tools {
namespace {

using namespace eprosima::fastdds::dds;
using Clock = std::chrono::steady_clock;

}  // namespace

int run_alarm_ack(const GlobalOptions& o, const std::string& code, const std::string& kind) {
  const double timeout = o.timeout.value_or(5.0);
  const auto deadline = wait_end(o, timeout);
  const std::string vehicle = o.vehicle.value_or(std::string());
  pmu::v5::AlarmSource source = pmu::v5::SOURCE_PMU;
  if (kind == "battery")
    source = pmu::v5::SOURCE_BATTERY;
  else if (kind == "mppt")
    source = pmu::v5::SOURCE_MPPT;
  else if (kind == "bus")
    source = pmu::v5::SOURCE_BUS;
  else if (kind != "pmu")
    return fail(o, ExitStatus::BadUsage, "--kind '" + pmu::service::printable(kind) + "': pmu, battery, mppt or bus");
  if (source == pmu::v5::SOURCE_BUS && o.bus.empty())
    return fail(o, ExitStatus::BadUsage, "a bus alarm needs --bus");
  if ((source == pmu::v5::SOURCE_BATTERY || source == pmu::v5::SOURCE_MPPT) && (o.bus.empty() || !o.address))
    return fail(o, ExitStatus::BadUsage, "a " + kind + " alarm needs --bus and --address (the " +
                                             (source == pmu::v5::SOURCE_BATTERY ? "CANopen node" : "MPPT device id") +
                                             ")");
  ContextLease lease(o, kPmuctlParticipant);
  pmu::dds::DdsContext& dds = *lease;
  DataReader& replies = dds.reader(
      dds.topic(topics::kAlarmAckReply, TypeSupport(new idl::Guarded<pmu::v5::AlarmAckReplyPubSubType>())),
      qos_profiles::kCommand);
  DataWriter& writer =
      dds.writer(dds.topic(topics::kAlarmAck, TypeSupport(new pmu::v5::AlarmAckPubSubType())), qos_profiles::kCommand);
  std::string bus = o.bus;
  std::uint16_t device = source == pmu::v5::SOURCE_BUS ? 0 : o.address.value_or(0);
  if (source == pmu::v5::SOURCE_PMU)
    if (const auto failed = resolve_target(o, vehicle, dds, deadline, bus, device)) return *failed;
  if (const auto failed = wait_for_match(o, dds, writer, replies, vehicle, deadline, "accepts alarm acknowledgements"))
    return *failed;

  pmu::v5::AlarmAck a;
  const std::string id = request_id();
  a.request_id(id);
  a.vehicle(vehicle);
  a.bus(bus);
  a.kind(source);
  a.device(device);
  a.code(code);
  // The end of this wait, which finding the PMU and the match have used part of: an
  // acknowledgement pmuctl gave up on is never applied (docs/safety.md H9).
  a.expires_at(o.deadline_ns ? o.deadline_ns : epoch_ns_at(deadline));
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
    pmu::v5::AlarmAckReply r;
    SampleInfo info;
    while (replies.take_next_sample(&r, &info) == ReturnCode_t::RETCODE_OK) {
      if (!info.valid_data || r.request_id().to_string() != id || r.vehicle().to_string() != vehicle) continue;
      const bool done = r.result() == pmu::v5::ACK_COMPLETED;
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
  if (!o.address || *o.address != codec::kBroadcastAddress || kind == pmu::v5::ENGINE_STOP) return {};
  return "--address 65535 (broadcast) is only for `engine stop`: every other command names one PMU";
}

int run_command(const GlobalOptions& o, const CommandSpec& spec) {
  const double timeout = o.timeout.value_or(5.0);
  const auto deadline = wait_end(o, timeout);
  CommandChannel channel(o);
  // A stop to the broadcast address needs no PMU seen: with --bus it goes to that bus, without
  // to every bus of the service (bus ""), so an engine can be stopped whatever the service
  // has read so far.
  const bool broadcast = spec.kind == pmu::v5::ENGINE_STOP && o.address && *o.address == codec::kBroadcastAddress;
  std::string bus = broadcast ? o.bus : std::string();
  std::uint16_t address = broadcast ? codec::kBroadcastAddress : 0;
  using Find = CommandChannel::Find;
  if (const auto failed = channel.open(deadline, bus, address, broadcast ? Find::Broadcast : Find::MayRecall))
    return *failed;

  const auto timeout_left = [&deadline] {
    return std::max(0.0, std::chrono::duration<double>(deadline - Clock::now()).count());
  };
  // Expires when its caller stops waiting (docs/safety.md H9).
  auto out = channel.send(spec, bus, address, timeout_left(), o.deadline_ns);
  // The PMU this agent's worker commanded before is no longer there (it moved, or its service
  // restarted without it); the service executed nothing, so the command goes, under a new
  // request id, to the PMU found now.
  if (channel.recalled_target_gone(out, bus, address)) {
    if (const auto failed = channel.open(deadline, bus, address)) return *failed;
    out = channel.send(spec, bus, address, timeout_left(), o.deadline_ns);
  }
  if (!out.written) return fail(o, ExitStatus::NotDone, "the command could not be written to DDS");
  if (const auto& r = out.reply) {
    // A bus the service does not serve, or no such device on it, is no such target (2), as
    // when pmuctl finds that out itself; the service executed nothing (interface.md 3.2).
    const ExitStatus status =
        r->result() == pmu::v5::COMPLETED ? ExitStatus::Ok
        : r->result() == pmu::v5::REJECTED && pmu::service::says_no_such_target(r->reason().to_string(), bus, address)
            ? ExitStatus::BadUsage
            : ExitStatus::NotDone;
    if (o.json) {
      Json j{{"request_id", out.request_id},
             {"vehicle", r->vehicle().to_string()},
             {"bus", r->bus().to_string()},
             {"address", r->address()},
             {"result", result_name(r->result())},
             {"reason", r->reason().to_string()}};
      if (r->has_value()) j["value"] = r->value();
      if (!(r->value_text().size() == 0)) j["value_text"] = r->value_text().to_string();
      // A failure of status 2 or 3 carries its status on its line (interface.md 3.2).
      if (status == ExitStatus::BadUsage) j["exit_status"] = static_cast<int>(status);
      std::printf("%s\n", j.dump(-1, ' ', false, nlohmann::json::error_handler_t::replace).c_str());
    } else if (r->has_value() || !(r->value_text().size() == 0)) {
      if (!(r->value_text().size() == 0))
        std::printf("%s\n", r->value_text().c_str());
      else
        std::printf("%g\n", r->value());
    }
    std::fprintf(stderr, "%s%s%s\n", result_name(r->result()), (r->reason().size() == 0) ? "" : ": ", r->reason().c_str());
    return static_cast<int>(status);
  }
  char waited[96];
  std::snprintf(waited, sizeof waited, "no reply from pmu-service within %.1f s (request ", timeout);
  const std::string message = waited + out.request_id + ")";
  std::fprintf(stderr, "pmuctl: %s\n", message.c_str());
  if (o.json) {
    // The line of a reply that never came: the same keys, a null result.
    Json j{{"request_id", out.request_id}, {"vehicle", channel.vehicle()}, {"bus", bus},
           {"address", address},           {"result", nullptr},           {"reason", message},
           {"exit_status", static_cast<int>(ExitStatus::NoAnswer)}};
    std::printf("%s\n", j.dump(-1, ' ', false, nlohmann::json::error_handler_t::replace).c_str());
  }
  return static_cast<int>(ExitStatus::NoAnswer);
}

}  // namespace pmu::tools
