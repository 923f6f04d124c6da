#include "pmu/dispatch/alarm_ack_service.hpp"

#include <spdlog/spdlog.h>

#include <algorithm>

#include "sender_key.hpp"

namespace pmu::service {
namespace {

using Reject = codec::Unexpected<std::string>;
using Source = alarms::DeviceKind;  // whose alarm: the session room has a DeviceKind of its own

// The numbers of idl/alarms.idl's AlarmSource, which dds_alarm_acks.cpp checks.
std::optional<Source> kind_of(std::int64_t source) noexcept {
  switch (source) {
    case 0: return Source::Pmu;
    case 1: return Source::Battery;
    case 2: return Source::Mppt;
    case 3: return Source::Bus;
    default: return std::nullopt;
  }
}

std::string content_of(const AlarmAckSample& s) {
  return s.vehicle + '\0' + s.bus + '\0' + std::to_string(s.kind) + '\0' + std::to_string(s.device) + '\0' + s.code;
}

std::string where(const AlarmAckSample& s) {
  return printable(s.code, kMaxAlarmCodeLength + 1) + " on " + printable(s.bus, kMaxBusNameLength + 1) + "/" +
         (s.kind == 3 ? std::string("bus") : std::to_string(s.device));
}

AlarmAckReplyData reply_to(const AlarmAckSample& s, AckReplyResult result, std::string reason,
                           alarms::AlarmState state = alarms::AlarmState::Normal) {
  return {s.request_id.substr(0, kMaxRequestIdLength),
          s.bus.substr(0, kMaxBusNameLength),
          kind_of(s.kind) ? s.kind : 0,
          s.device,
          s.code.substr(0, kMaxAlarmCodeLength),
          result,
          reason.substr(0, kMaxAckReasonLength),
          state};
}

}  // namespace

std::string_view to_string(AckReplyResult r) noexcept {
  return r == AckReplyResult::Completed ? "COMPLETED" : "REJECTED";
}

codec::Result<AlarmAckRequest, std::string> parse_alarm_ack(const AlarmAckSample& s, const std::string& vehicle,
                                                            const Now& now, const Lifetimes& lifetimes) {
  if (s.request_id.empty()) return Reject{"request_id is empty"};
  if (s.request_id.size() > kMaxRequestIdLength)
    return Reject{"request_id is " + std::to_string(s.request_id.size()) + " bytes long; at most " +
                  std::to_string(kMaxRequestIdLength)};
  if (s.vehicle != vehicle)
    return Reject{"vehicle '" + printable(s.vehicle, 16) + "' is not this service's ('" + printable(vehicle) + "')"};
  if (s.bus.empty() || s.bus.size() > kMaxBusNameLength)
    return Reject{"bus: a bus name of 1 to " + std::to_string(kMaxBusNameLength) + " bytes"};
  const auto kind = kind_of(s.kind);
  if (!kind) return Reject{"kind " + std::to_string(s.kind) + " is not an AlarmSource"};
  if (*kind == Source::Bus && s.device != 0) return Reject{"device must be 0 for a bus alarm"};
  const auto code = s.code.size() <= kMaxAlarmCodeLength ? alarms::code_named(s.code) : std::nullopt;
  if (!code) return Reject{"code '" + printable(s.code, 32) + "' is not an alarm code"};
  if (!alarms::applies_to(alarms::spec_of(*code), *kind))
    return Reject{"code " + std::string(alarms::to_string(*code)) + " is not an alarm of a " +
                  std::string(alarms::to_string(*kind))};
  auto expires = deadline(s.expires_at, now, lifetimes);
  if (!expires) return Reject{"expires_at: " + expires.error()};
  return AlarmAckRequest{s.sender, s.request_id, s.bus, *kind, s.device, *code, *expires};
}

AlarmAckService::AlarmAckService(std::vector<BusWorker*> workers, std::string vehicle, Lifetimes lifetimes,
                                 const transport::Clock& clock, AckReplyFn reply)
    : workers_(std::move(workers)),
      vehicle_(std::move(vehicle)),
      lifetimes_(lifetimes),
      clock_(clock),
      reply_(std::move(reply)) {}

std::size_t AlarmAckService::remembered() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return seen_.size();
}

void AlarmAckService::set_role_gate(std::function<bool()> applies_now) { applies_now_ = std::move(applies_now); }

void AlarmAckService::let_go(const std::string& key, const AlarmAckSample& s) {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    auto it = seen_.find(key);
    if (it == seen_.end() || it->second.final) return;
    seen_.erase(it);
    if (auto at = std::find(order_.begin(), order_.end(), key); at != order_.end()) order_.erase(at);
  }
  spdlog::warn("audit: alarm ack {} from {}: {}: not answered here: this instance stopped owning the bus",
               printable(s.request_id), printable(s.sender), where(s));
}

void AlarmAckService::submit(const AlarmAckSample& s) {
  if (!applies_now()) {
    spdlog::info("audit: alarm ack {} from {}: {} -> not applied, not answered: this instance does not own the bus",
                 printable(s.request_id), printable(s.sender), where(s));
    return;
  }
  const std::string key = sender_key(s.sender, s.request_id);
  // Without an id nothing can be matched to a resend: answered, never remembered.
  if (!s.request_id.empty() && !first_time(key, s)) return;
  auto parsed = parse_alarm_ack(s, vehicle_, Now{clock_.system_now(), clock_.steady_now()}, lifetimes_);
  if (!parsed) return finish(key, s, reply_to(s, AckReplyResult::Rejected, parsed.error()));
  const AlarmAckRequest r = *parsed;
  for (auto* w : workers_)
    if (w->config().name == r.bus)
      return w->post([this, w, r, s] {
        if (clock_.steady_now() > r.expires)
          return finish(sender_key(r.sender, r.request_id), s,
                        reply_to(s, AckReplyResult::Rejected, "expired before the bus worker took it"));
        if (!applies_now()) return let_go(sender_key(r.sender, r.request_id), s);
        apply(*w, r);
      });
  finish(key, s, reply_to(s, AckReplyResult::Rejected, "bus " + printable(r.bus) + " is not served"));
}

bool AlarmAckService::first_time(const std::string& key, const AlarmAckSample& s) {
  std::optional<AlarmAckReplyData> again;
  bool reused = false;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    if (auto it = seen_.find(key); it != seen_.end()) {
      if (it->second.content != content_of(s))
        reused = true;
      else if (it->second.final)
        again = it->second.final;
      else
        ++it->second.owed;
    } else {
      seen_.emplace(key, Entry{content_of(s), std::nullopt, 0});
      order_.push_back(key);
      while (order_.size() > kRememberedRequests) {
        seen_.erase(order_.front());
        order_.pop_front();
      }
      return true;
    }
  }
  if (reused) {
    spdlog::warn("audit: alarm ack {} from {} reuses that id for another acknowledgement: {} -> REJECTED",
                 printable(s.request_id), printable(s.sender), where(s));
    send_reply(reply_to(s, AckReplyResult::Rejected,
                        "request id was already used by this sender for another acknowledgement (use a new id)"));
    return false;
  }
  spdlog::info("audit: duplicate alarm ack {} from {}: answered again, not applied", printable(s.request_id),
               printable(s.sender));
  if (again) send_reply(*again);  // else owed: sent with the first one's reply
  return false;
}

void AlarmAckService::apply(BusWorker& worker, const AlarmAckRequest& r) {
  const auto now = clock_.steady_now();
  const auto wall = clock_.system_now();
  const alarms::AlarmSet* set = nullptr;
  alarms::AckResult done = alarms::AckResult::NotFound;
  switch (r.kind) {
    case Source::Pmu:
      if (auto* session = worker.session(r.device)) {
        done = session->acknowledge_alarm(r.code, now, wall);
        set = &session->alarms();
      }
      break;
    case Source::Battery:
    case Source::Mppt:
      if (auto* session = worker.canopen_session(
              r.kind == Source::Battery ? service::DeviceKind::Battery : service::DeviceKind::Mppt, r.device)) {
        done = session->acknowledge_alarm(r.code, now, wall);
        set = &session->alarms();
      }
      break;
    case Source::Bus:
      done = worker.acknowledge_bus_alarm(r.code);
      set = &worker.bus_alarms();
      break;
    case Source::AnyDevice: break;  // parse_alarm_ack never lets it through
  }
  const alarms::Alarm* alarm = set ? set->find(r.code) : nullptr;
  const auto state = alarm ? alarm->state() : alarms::AlarmState::Normal;
  AlarmAckSample asked{r.sender,
                       r.request_id,
                       vehicle_,
                       r.bus,
                       static_cast<std::int64_t>(r.kind),
                       r.device,
                       std::string(alarms::to_string(r.code)),
                       0};
  const std::string key = sender_key(r.sender, r.request_id);
  switch (done) {
    case alarms::AckResult::Acknowledged:
      return finish(key, asked, reply_to(asked, AckReplyResult::Completed, "acknowledged", state));
    case alarms::AckResult::NothingToAcknowledge:
      return finish(key, asked,
                    reply_to(asked, AckReplyResult::Completed,
                             "nothing to acknowledge: " + std::string(alarms::to_string(state)), state));
    case alarms::AckResult::NotFound:
      return finish(key, asked, reply_to(asked, AckReplyResult::Rejected, "no such alarm"));
  }
}

void AlarmAckService::finish(const std::string& key, const AlarmAckSample& s, AlarmAckReplyData reply) {
  if (!applies_now()) return let_go(key, s);
  unsigned copies = 1;
  if (!s.request_id.empty()) {
    std::lock_guard<std::mutex> lock(mutex_);
    if (auto it = seen_.find(key); it != seen_.end()) {
      if (it->second.final) return;  // never a second final reply
      it->second.final = reply;
      copies += it->second.owed;
      it->second.owed = 0;
    }
  }
  spdlog::info("audit: alarm ack {} from {}: {} -> {}: {}", printable(s.request_id), printable(s.sender), where(s),
               to_string(reply.result), reply.reason);
  for (unsigned i = 0; i < copies; ++i) send_reply(reply);
}

void AlarmAckService::send_reply(const AlarmAckReplyData& reply) {
  if (!applies_now()) {
    spdlog::warn(
        "audit: the reply to alarm ack {} was not sent: this instance stopped owning the bus before it went out; the "
        "new owner answers the client's resend",
        printable(reply.request_id));
    return;
  }
  reply_(reply);
}

}  // namespace pmu::service
