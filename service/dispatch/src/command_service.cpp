#include "pmu/dispatch/command_service.hpp"

#include <spdlog/spdlog.h>

#include <algorithm>
#include <cstdio>
#include <memory>

#include "pmu/alarms/settings.hpp"
#include "pmu/codec/encode.hpp"
#include "pmu/dispatch/command_reply.hpp"
#include "pmu/codec/ids.hpp"
#include "sender_key.hpp"

namespace pmu::service {

CommandService::CommandService(std::vector<BusWorker*> workers, PolicyConfig policy, Timeouts timeouts,
                               const transport::Clock& clock, ReplyFn reply)
    : workers_(std::move(workers)),
      policy_(policy),
      timeouts_(timeouts),
      clock_(clock),
      reply_(std::move(reply)),
      record_(policy.lifetimes) {}

BusWorker* CommandService::worker_for(const std::string& bus) const {
  for (auto* w : workers_)
    if (w->config().name == bus) return w;
  return nullptr;
}

CommandService::Counters CommandService::counters() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return counters_;
}

std::size_t CommandService::remembered() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return seen_.size();
}

void CommandService::link_configured() {
  std::lock_guard<std::mutex> lock(mutex_);
  slow_link_.quiet();
}

void CommandService::set_role_gate(std::function<bool()> executes_now) { executes_now_ = std::move(executes_now); }

std::size_t CommandService::recorded() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return record_.size();
}

void CommandService::peer_reply(const CommandReplyData& reply) {
  if (executes_now()) return;  // this instance writes the replies: nobody else's count
  std::lock_guard<std::mutex> lock(mutex_);
  ++counters_.peer_replies;
  record_.peer_reply(reply, clock_.steady_now());
}

void CommandService::heard_on_can(const std::string& bus, const codec::CanFrame& frame, SteadyTime at) {
  if (executes_now()) return;
  std::lock_guard<std::mutex> lock(mutex_);
  record_.heard(bus, frame, at);
}

namespace {

std::string sender_of_key(const std::string& key) { return key.substr(0, key.find('\0')); }

std::string recorded_what(const CommandReplyData& r) {
  return std::string(to_string(r.kind)) + " to " + printable(r.bus) + "/" + std::to_string(r.address);
}

}  // namespace

void CommandService::took_over(SteadyTime now) {
  std::vector<FailoverRecord::Verdict> verdicts;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    if (record_.empty()) return;
    verdicts = record_.take_over(now);
    for (auto& v : verdicts) {
      // Taken here before (this instance owned the bus earlier): its own memory answers it.
      if (seen_.count(v.key)) {
        v.key.clear();
        continue;
      }
      Entry e{v.fingerprint, std::nullopt, {}, 0};
      // "Outcome unknown" waits for the client to ask again: the former owner's own reply may
      // have reached the client and not this instance (it stopped between the two), and a
      // second final reply that contradicts the first is worse than one that comes on a resend.
      if (v.action == FailoverRecord::Action::Answered || v.action == FailoverRecord::Action::Unknown) {
        e.final = v.reply;
        e.final_at = now;
      }
      seen_.emplace(v.key, std::move(e));
      order_.push_back(v.key);
      while (order_.size() > kRememberedRequests) {
        seen_.erase(order_.front());
        order_.pop_front();
      }
    }
  }
  // Stops first: none waits behind the others' replies (docs/safety.md H4).
  std::stable_partition(verdicts.begin(), verdicts.end(), [](const FailoverRecord::Verdict& v) {
    return v.action == FailoverRecord::Action::Run && v.reply.kind == CommandKind::EngineStop;
  });
  for (const auto& v : verdicts) {
    if (v.key.empty()) continue;
    const std::string sender = sender_of_key(v.key);
    switch (v.action) {
      case FailoverRecord::Action::Answered:
        spdlog::info("audit: command {} from {}: {} -> {} by the former bus owner; not executed here",
                     printable(v.reply.request_id), printable(sender), recorded_what(v.reply),
                     to_string(v.reply.result));
        break;
      case FailoverRecord::Action::Unknown:
        spdlog::warn("audit: command {} from {}: {} -> {}: {}; answered when it is sent again",
                     printable(v.reply.request_id), printable(sender), recorded_what(v.reply),
                     to_string(v.reply.result), v.reply.reason);
        break;
      case FailoverRecord::Action::Expired: finish(v.key, sender, recorded_what(v.reply), v.reply); break;
      case FailoverRecord::Action::Run:
        if (v.reply.kind == CommandKind::EngineStop) {
          // Whatever its expiry: a late stop only ends cranking, a lost one is H4.
          CommandSample stop = *v.sample;
          stop.expires_at = 0;
          admit(v.key, stop, Now{clock_.system_now(), clock_.steady_now()});
        } else {
          admit(v.key, *v.sample, v.arrived);
        }
        break;
    }
  }
}

void CommandService::relinquish(const std::string& key, const CommandReplyData& reply) {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    auto it = seen_.find(key);
    if (it == seen_.end() || it->second.final) return;
    const auto fingerprint = it->second.fingerprint;
    seen_.erase(it);
    if (auto at = std::find(order_.begin(), order_.end(), key); at != order_.end()) order_.erase(at);
    record_.relinquished(key, fingerprint, reply, clock_.steady_now());
  }
  spdlog::warn(
      "audit: command {} from {}: {}: not answered here: this instance stopped owning the bus while it ran; the "
      "new owner answers it",
      printable(reply.request_id), printable(sender_of_key(key)), recorded_what(reply));
}

CommandService::Seen CommandService::remember(const std::string& key, const CommandSample& s,
                                              std::optional<CommandReplyData>& again,
                                              std::optional<std::chrono::nanoseconds>& slow_link) {
  const std::uint64_t fingerprint = content_fingerprint(s);
  std::lock_guard<std::mutex> lock(mutex_);
  ++counters_.received;
  if (auto it = seen_.find(key); it != seen_.end()) {
    if (it->second.fingerprint != fingerprint) {
      ++counters_.reused_ids;
      return Seen::Reused;
    }
    ++counters_.duplicates;
    if (it->second.final) {
      again = it->second.final;
      const auto out_for = clock_.steady_now() - it->second.final_at;
      if (out_for >= SlowLinkHint::kReplyOut) ++counters_.resends_after_reply;
      if (slow_link_.resend(s.sender, out_for)) slow_link = out_for;
    } else {
      ++it->second.owed;
    }
    return Seen::Resend;
  }
  seen_.emplace(key, Entry{fingerprint, std::nullopt, {}, 0});
  order_.push_back(key);
  while (order_.size() > kRememberedRequests) {
    seen_.erase(order_.front());
    order_.pop_front();
  }
  return Seen::New;
}

void CommandService::finish(const std::string& key, const std::string& sender, const std::string& what,
                            const CommandReplyData& reply) {
  if (!executes_now()) return relinquish(key, reply);
  if (!is_final(reply.result)) {
    // Progress of a long command (an engine start): passed on, neither recorded as the
    // answer to resends nor counted; the audit line is the final reply's.
    spdlog::debug("command {} from {}: {} -> {}: {}", printable(reply.request_id), printable(sender), what,
                  to_string(reply.result), reply.reason);
    send_reply(reply);
    return;
  }
  unsigned copies = 1;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    if (auto it = seen_.find(key); it != seen_.end()) {
      if (it->second.final) return;  // already answered: never a second final reply
      it->second.final = reply;
      it->second.final_at = clock_.steady_now();
      copies += it->second.owed;
      it->second.owed = 0;
    }
    if (reply.result == CommandResult::Completed)
      ++counters_.completed;
    else if (reply.result == CommandResult::Timeout || reply.result == CommandResult::Failed)
      ++counters_.failed;
    else
      ++counters_.refused;
  }
  // Reasons quote network text only through printable(); ids and senders are escaped here.
  spdlog::info("audit: command {} from {}: {} -> {}{}{}", printable(reply.request_id), printable(sender), what,
               to_string(reply.result), reply.reason.empty() ? "" : ": ", reply.reason);
  for (unsigned i = 0; i < copies; ++i) send_reply(reply);
}

void CommandService::send_reply(const CommandReplyData& reply) {
  if (!executes_now()) {
    spdlog::warn(
        "audit: the reply {} to command {} was not sent: this instance stopped owning the bus before it went out; "
        "the new owner answers the client's resend",
        to_string(reply.result), printable(reply.request_id));
    return;
  }
  reply_(reply);
}

void CommandService::answer(const CommandRequest& r, CommandResult result, std::string reason) {
  finish(sender_key(r.sender, r.request_id), r.sender, describe(r), make_reply(r, result, std::move(reason)));
}

void CommandService::refuse(const CommandRequest& r, const Refusal& refusal) {
  answer(r, refusal.result, refusal.reason);
}

// The stages, in order. Each either lets the command on or says why not; every refusal is
// one final reply, published outside the lock, with nothing sent to a bus.

void CommandService::submit(const CommandSample& s) {
  const Now now{clock_.system_now(), clock_.steady_now()};
  if (!executes_now()) {
    // The bus owner executes and answers it; kept for a takeover (failover_record.hpp).
    if (s.request_id.empty()) return;
    {
      std::lock_guard<std::mutex> lock(mutex_);
      record_.request(sender_key(s.sender, s.request_id), s, now);
    }
    spdlog::info("audit: command {} from {}: {} -> not executed, not answered: this instance does not own the bus",
                 printable(s.request_id), printable(s.sender), describe(s));
    return;
  }
  took_over(now.steady);  // nothing to do unless the gate has just opened
  if (s.request_id.empty()) return reject_without_id(s);
  const std::string key = sender_key(s.sender, s.request_id);
  if (!first_time(key, s)) return;
  admit(key, s, now);
}

void CommandService::admit(const std::string& key, const CommandSample& s, const Now& now) {
  // Values, ranges and the expiry: parse_command checks them all.
  auto parsed = parse_command(s, now, policy_.lifetimes);
  if (!parsed) return finish(key, s.sender, describe(s), make_reply(s, CommandResult::Rejected, parsed.error()));
  const CommandRequest& r = *parsed;
  // parse_command lets only engine_stop through to the broadcast address; a stop is never
  // judged nor held back by the rate limit.
  if (r.bus.empty() && r.address == codec::kBroadcastAddress) return broadcast_on_every_bus(r);
  BusWorker* worker = worker_for(r.bus);
  if (!worker) return refuse(r, not_served(r));
  if (auto no = limit_rate(r)) return refuse(r, *no);
  // A stop waits behind no other command posted to the worker, nor behind the frames of its
  // turn (docs/safety.md H4).
  if (r.kind() == CommandKind::EngineStop) return worker->post_urgent([this, worker, r] { run_on_worker(*worker, r); });
  worker->post([this, worker, r] { run_on_worker(*worker, r); });
}

void CommandService::reject_without_id(const CommandSample& s) {
  // Nothing to correlate a resend with: answered, not remembered.
  {
    std::lock_guard<std::mutex> lock(mutex_);
    ++counters_.received;
    ++counters_.refused;
  }
  spdlog::warn("audit: command without request_id from {}: {} -> REJECTED", printable(s.sender), describe(s));
  send_reply(make_reply(s, CommandResult::Rejected, "request_id is empty"));
}

bool CommandService::first_time(const std::string& key, const CommandSample& s) {
  std::optional<CommandReplyData> again;
  std::optional<std::chrono::nanoseconds> slow_link;
  switch (remember(key, s, again, slow_link)) {
    case Seen::New: return true;
    case Seen::Resend:
      spdlog::info("audit: duplicate command {} from {}: answered again, not executed", printable(s.request_id),
                   printable(s.sender));
      if (slow_link)
        spdlog::info(
            "DDS: a client asked again for a reply this service had published {:.1f} s before, and so did another "
            "before it: their link has a round trip or a loss a LAN does not have. On a radio link, `link: {{profile: "
            "radio}}` here and `--link radio` on the ground set what it needs (interface.md 7.3)",
            std::chrono::duration<double>(*slow_link).count());
      if (again) send_reply(*again);  // else owed: sent with the first one's final reply
      return false;
    case Seen::Reused:
      spdlog::warn("audit: command {} from {} reuses that id for another command: {} -> REJECTED",
                   printable(s.request_id), printable(s.sender), describe(s));
      send_reply(make_reply(s, CommandResult::Rejected,
                            "request id '" + printable(s.request_id) +
                                "' was already used by this sender for another command; not executed (use a new id)"));
      return false;
  }
  return false;
}

// From the session, on its worker's thread: how the service gets the device's packets, which
// of them its alarms read, and its internal temperature while fresh. What is not known is
// left at DeviceUse's worst case.
DeviceUse CommandService::device_use(const DeviceSession& session, SteadyTime now) {
  DeviceUse use;
  use.streaming = session.settings().mode == TelemetryMode::Streaming;
  use.packets_needed = alarms::packets_read(session.settings().alarms);
  use.internal_temperature = session.internal_temperature(now);
  return use;
}

CommandService::Refusal CommandService::not_served(const CommandRequest& r) const {
  std::string served;
  for (auto* w : workers_) served += (served.empty() ? "" : ", ") + w->config().name;
  return {CommandResult::Rejected, bus_not_served_reason(r.bus, served)};
}

std::optional<CommandService::Refusal> CommandService::judge(const CommandRequest& r, const DeviceUse& use) const {
  PolicyVerdict verdict = check_policy(r, policy_, use);
  if (verdict.allowed()) return std::nullopt;
  return Refusal{verdict.result, std::move(verdict.reason)};
}

std::optional<CommandService::Refusal> CommandService::limit_rate(const CommandRequest& r) {
  if (r.kind() == CommandKind::EngineStop) return std::nullopt;  // a stop is never held back
  {
    std::lock_guard<std::mutex> lock(mutex_);
    auto it = limiters_.try_emplace({r.bus, r.address}, policy_.rate_per_second, policy_.burst).first;
    if (it->second.allow(clock_.steady_now())) return std::nullopt;
  }
  char buf[96];
  std::snprintf(buf, sizeof buf, "rate limit: more than %g commands/s (burst %g) to this device",
                policy_.rate_per_second, policy_.burst);
  return Refusal{CommandResult::Rejected, buf};
}

void CommandService::run_on_worker(BusWorker& worker, const CommandRequest& r) {
  // The gate closed since it was posted: the new owner has it (and this instance's record, if
  // it takes the bus back).
  if (!executes_now()) return relinquish(sender_key(r.sender, r.request_id), make_reply(r, CommandResult::Failed, {}));
  if (r.address == codec::kBroadcastAddress) return broadcast(worker, r);
  DeviceSession* session = worker.session(r.address);
  // A stop to the address a unit has just left follows the unit (interface.md 2.6): whoever
  // sent it meant that unit, and the address it left reaches nothing (docs/safety.md H4).
  if (!session && r.kind() == CommandKind::EngineStop) session = worker.session_moved_from(r.address);
  if (auto no = check_device(worker, session, r)) return refuse(r, *no);
  if (auto no = judge(r, device_use(*session, clock_.steady_now()))) return refuse(r, *no);
  if (auto no = check_hold(r)) return refuse(r, *no);
  execute_command(*session, r, clock_.steady_now(), timeouts_,
                  [this, key = sender_key(r.sender, r.request_id), sender = r.sender,
                   what = describe(r)](const CommandReplyData& d) { finish(key, sender, what, d); });
}

void CommandService::broadcast(BusWorker& worker, const CommandRequest& r) {
  // parse_command lets only engine_stop through to the broadcast address; no device answers.
  stop_engine_starts(worker, r.request_id);
  const auto sent = worker.bus().send(*codec::encode_engine_stop(r.address), timeouts_.send);
  if (sent.ok()) return answer(r, CommandResult::Completed, "stop sent to every PMU (broadcast)");
  answer(r, CommandResult::Failed, "bus refused the engine stop: " + std::string(transport::to_string(sent.status)));
}

void CommandService::stop_engine_starts(BusWorker& worker, const std::string& request_id) {
  const auto now = clock_.steady_now();
  for (const auto address : worker.addresses())
    if (auto* s = worker.session(address)) s->on_engine_stop(request_id, now);
}

void CommandService::broadcast_on_every_bus(const CommandRequest& r) {
  if (workers_.empty()) return answer(r, CommandResult::Failed, "this service serves no bus");
  // Each bus is sent to on its own worker's thread; the last one to finish answers, so the
  // request still gets exactly one final reply.
  struct Round {
    std::mutex mutex;
    std::size_t left;
    std::string sent, refused;
  };
  auto round = std::make_shared<Round>();
  round->left = workers_.size();
  for (auto* w : workers_)
    w->post_urgent([this, w, r, round] {
      stop_engine_starts(*w, r.request_id);
      const auto sent = w->bus().send(*codec::encode_engine_stop(codec::kBroadcastAddress), timeouts_.send);
      std::string done, failed;
      {
        std::lock_guard<std::mutex> lock(round->mutex);
        std::string& list = sent.ok() ? round->sent : round->refused;
        list += (list.empty() ? "" : ", ") + w->config().name +
                (sent.ok() ? std::string() : " (" + std::string(transport::to_string(sent.status)) + ")");
        if (--round->left > 0) return;
        done = round->sent;
        failed = round->refused;
      }
      if (failed.empty()) return answer(r, CommandResult::Completed, "stop sent to every PMU (broadcast) on " + done);
      answer(r, CommandResult::Failed,
             "bus refused the engine stop: " + failed + (done.empty() ? std::string() : "; sent on " + done));
    });
}

std::optional<CommandService::Refusal> CommandService::check_hold(const CommandRequest& r) {
  std::optional<std::string> held;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    held = holds_.admit(r, clock_.steady_now());
  }
  if (!held) return std::nullopt;
  return Refusal{CommandResult::Denied, std::move(*held)};
}

std::optional<CommandService::Refusal> CommandService::check_device(BusWorker& worker, const DeviceSession* session,
                                                                    const CommandRequest& r) {
  const std::string device = "device " + std::to_string(r.address);
  if (!session) return Refusal{CommandResult::Rejected, device_not_seen_reason(r.address, r.bus)};
  // Firmware decides what a command may do; a stop needs nothing read.
  if (!session->info() && r.kind() != CommandKind::EngineStop)
    return Refusal{CommandResult::Rejected,
                   device + " on " + r.bus + " is not ready: its firmware and configuration have not been read yet"};
  if (const auto* set = std::get_if<action::SetParameter>(&r.action);
      set && set->parameter == codec::Parameter::CanAddress && set->raw != r.address &&
      worker.session(static_cast<std::uint16_t>(set->raw)))
    return Refusal{CommandResult::Rejected, "address " + std::to_string(set->raw) + " is already in use on " + r.bus};
  return std::nullopt;
}

}  // namespace pmu::service
