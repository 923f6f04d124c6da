#include "pmu/service/command_service.hpp"

#include <spdlog/spdlog.h>

#include <cmath>
#include <cstdio>

#include "pmu/codec/encode.hpp"
#include "pmu/codec/ids.hpp"

namespace pmu::service {
namespace {

// Request ids remembered for duplicate detection: far more than any burst in flight.
constexpr std::size_t kRemembered = 16384;

}  // namespace

CommandService::CommandService(std::vector<BusWorker*> workers, PolicyConfig policy, Timeouts timeouts,
                               const transport::Clock& clock, ReplyFn reply)
    : workers_(std::move(workers)), policy_(policy), timeouts_(timeouts), clock_(clock), reply_(std::move(reply)) {}

BusWorker* CommandService::worker_for(const std::string& bus) const {
  for (auto* w : workers_)
    if (w->config().name == bus) return w;
  return nullptr;
}

CommandService::Counters CommandService::counters() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return counters_;
}

void CommandService::answer_now(const CommandRequest& r, CommandResult result, std::string reason) {
  finish(make_reply(r, result, std::move(reason)));
}

void CommandService::finish(const CommandReplyData& reply) {
  unsigned copies = 1;
  std::string what, sender;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    auto it = seen_.find(reply.request_id);
    if (it != seen_.end()) {
      if (it->second.final) return;  // already answered: never a second final reply
      it->second.final = reply;
      copies += it->second.owed;
      it->second.owed = 0;
      what = it->second.what;
      sender = it->second.sender;
    }
    if (reply.result == CommandResult::Completed)
      ++counters_.completed;
    else if (reply.result == CommandResult::Timeout || reply.result == CommandResult::Failed)
      ++counters_.failed;
    else
      ++counters_.refused;
  }
  spdlog::info("audit: command {} from {}: {} -> {}{}{}", reply.request_id, sender, what, to_string(reply.result),
               reply.reason.empty() ? "" : ": ", reply.reason);
  for (unsigned i = 0; i < copies; ++i) reply_(reply);
}

void CommandService::submit(CommandRequest r) {
  const auto now_wall = clock_.system_now();
  const auto now = clock_.steady_now();
  if (r.request_id.empty()) {
    spdlog::warn("audit: command without request_id from {}: {} -> REJECTED", r.sender, describe(r));
    CommandReplyData d = make_reply(r, CommandResult::Rejected, "request_id is empty");
    reply_(d);
    return;
  }
  {
    std::lock_guard<std::mutex> lock(mutex_);
    ++counters_.received;
    auto it = seen_.find(r.request_id);
    if (it != seen_.end()) {
      ++counters_.duplicates;
      spdlog::info("audit: duplicate command {} from {}: answered again, not executed", r.request_id, r.sender);
      if (!it->second.final) {
        ++it->second.owed;
        return;
      }
      const CommandReplyData again = *it->second.final;
      reply_(again);
      return;
    }
    seen_[r.request_id] = Entry{std::nullopt, 0, describe(r), r.sender};
    order_.push_back(r.request_id);
    while (order_.size() > kRemembered) {
      seen_.erase(order_.front());
      order_.pop_front();
    }
  }

  const auto expires_wall = r.expires_at.value_or(now_wall + policy_.default_lifetime);
  if (now_wall > expires_wall) {
    const auto late = std::chrono::duration_cast<std::chrono::milliseconds>(now_wall - expires_wall).count();
    return answer_now(r, CommandResult::Rejected, "expired " + std::to_string(late) + " ms ago");
  }
  const auto expires = now + std::chrono::duration_cast<std::chrono::steady_clock::duration>(expires_wall - now_wall);

  BusWorker* worker = worker_for(r.bus);
  if (!worker) {
    std::string served;
    for (auto* w : workers_) served += (served.empty() ? "" : ", ") + w->config().name;
    return answer_now(r, CommandResult::Rejected, "bus '" + r.bus + "' is not served here (buses: " + served + ")");
  }
  if (r.address == codec::kBroadcastAddress && r.kind != CommandKind::EngineStop)
    return answer_now(r, CommandResult::Rejected, "broadcast (65535) is only accepted for engine_stop");

  const PolicyVerdict verdict = check_policy(r, policy_);
  if (!verdict.allowed()) return answer_now(r, verdict.result, verdict.reason);

  bool limited = false;
  if (r.kind != CommandKind::EngineStop) {
    std::lock_guard<std::mutex> lock(mutex_);
    auto it = limiters_.try_emplace({r.bus, r.address}, policy_.rate_per_second, policy_.burst).first;
    limited = !it->second.allow(now);
  }
  if (limited) {
    char buf[96];
    std::snprintf(buf, sizeof buf, "rate limit: more than %g commands/s (burst %g) to this device",
                  policy_.rate_per_second, policy_.burst);
    return answer_now(r, CommandResult::Rejected, buf);
  }

  worker->post([this, worker, r, expires] {
    const auto now_w = clock_.steady_now();
    if (r.address == codec::kBroadcastAddress) {
      const auto sent = worker->bus().send(*codec::encode_engine_stop(r.address), timeouts_.send);
      return sent.ok() ? answer_now(r, CommandResult::Completed, "stop sent to every PMU (broadcast)")
                       : answer_now(r, CommandResult::Failed,
                                    "bus refused the engine stop: " + std::string(transport::to_string(sent.status)));
    }
    DeviceSession* session = worker->session(r.address);
    if (!session)
      return answer_now(r, CommandResult::Rejected,
                        "device " + std::to_string(r.address) + " not seen on " + r.bus);
    if (!session->info() && r.kind != CommandKind::EngineStop)
      return answer_now(r, CommandResult::Rejected,
                        "device " + std::to_string(r.address) + " on " + r.bus +
                            " is not ready: its firmware and configuration have not been read yet");
    if (r.kind == CommandKind::SetParameter && r.parameter == "can_address" && std::isfinite(r.value) &&
        r.value >= 0 && r.value <= 65534 && worker->session(static_cast<std::uint16_t>(r.value)) &&
        static_cast<std::uint16_t>(r.value) != r.address)
      return answer_now(r, CommandResult::Rejected,
                        "address " + std::to_string(static_cast<int>(r.value)) + " is already in use on " + r.bus);
    execute_command(*session, r, now_w, expires, timeouts_, [this](const CommandReplyData& d) { finish(d); });
  });
}

}  // namespace pmu::service
