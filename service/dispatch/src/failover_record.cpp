#include "pmu/dispatch/failover_record.hpp"

#include <algorithm>
#include <utility>

#include "pmu/codec/packets.hpp"
#include "pmu/codec/parameters.hpp"
#include "pmu/dispatch/command_reply.hpp"

namespace pmu::service {
namespace failover_detail {

// The ids a value is set on and read from with a zero-length get (table 1: the stored
// parameters, the outputs, generation): a frame with data there is a set or a get's answer.
bool settable(codec::PacketId p) noexcept {
  return codec::parameter_from_packet(p).has_value() || p == codec::PacketId::Outputs ||
         p == codec::PacketId::Generation;
}

}  // namespace failover_detail

FrameRole frame_role(const codec::CanFrame& f) noexcept {
  if (!f.extended || f.remote) return FrameRole::Other;
  const auto parsed = codec::parse_id(f.id, true);
  // A broadcast can only be an engine stop among the commands, and a stop always runs.
  if (!parsed.id || parsed.id->address == codec::kBroadcastAddress) return FrameRole::Other;
  const auto packet = parsed.id->packet;
  using codec::PacketId;
  if (packet == PacketId::EnableOutputs || packet == PacketId::DisableOutputs)
    return f.length == 1 ? FrameRole::Command : FrameRole::Other;
  if (packet == PacketId::EngineStart || packet == PacketId::EngineStop || packet == PacketId::Reset)
    return f.length == 0 ? FrameRole::Command : FrameRole::Other;
  if (!failover_detail::settable(packet)) return FrameRole::Other;  // telemetry, polls, serial, firmware
  if (f.length == 0) return FrameRole::Get;
  const auto* spec = codec::find_packet(packet);
  return spec && f.length == spec->length ? FrameRole::Command : FrameRole::Other;
}

std::optional<codec::PacketId> command_packet(const CommandSample& s) noexcept {
  if (s.kind >= kCommandKindCount) return std::nullopt;
  switch (static_cast<CommandKind>(s.kind)) {
    case CommandKind::SetParameter: {
      const auto p = codec::parameter_from_name(s.parameter);
      if (!p) return std::nullopt;
      return codec::spec_of(*p).packet;
    }
    case CommandKind::SetOutputs: return codec::PacketId::Outputs;
    case CommandKind::EnableOutputs: return codec::PacketId::EnableOutputs;
    case CommandKind::DisableOutputs: return codec::PacketId::DisableOutputs;
    case CommandKind::SetGeneration: return codec::PacketId::Generation;
    case CommandKind::EngineStart: return codec::PacketId::EngineStart;
    case CommandKind::EngineStop: return codec::PacketId::EngineStop;
    case CommandKind::Reset: return codec::PacketId::Reset;
    case CommandKind::Get:
    case CommandKind::RequestMeasurements:
    case CommandKind::GetSerial:
    case CommandKind::GetFirmware: return std::nullopt;
  }
  return std::nullopt;
}

FailoverRecord::FailoverRecord(Lifetimes lifetimes, FailoverLimits limits) : lifetimes_(lifetimes), limits_(limits) {}

bool FailoverRecord::same_request(const CommandReplyData& a, const CommandReplyData& b) {
  return a.request_id == b.request_id && a.bus == b.bus && a.address == b.address && a.kind == b.kind;
}

void FailoverRecord::forget_old(SteadyTime now) {
  while (!order_.empty()) {
    auto it = entries_.find(order_.front());
    if (it != entries_.end() && it->second.arrived.steady + lifetimes_.max_lifetime >= now) break;
    if (it != entries_.end()) entries_.erase(it);
    order_.pop_front();
  }
  while (!replies_.empty() && replies_.front().second + lifetimes_.max_lifetime < now) replies_.pop_front();
  while (!frames_.empty() && frames_.front().at + limits_.can_slack < now) frames_.pop_front();
  while (!gets_.empty() && gets_.front().at + limits_.can_slack < now) gets_.pop_front();
}

void FailoverRecord::add(const std::string& key, Entry e) {
  entries_.emplace(key, std::move(e));
  order_.push_back(key);
  while (order_.size() > limits_.max_requests) {
    entries_.erase(order_.front());
    order_.pop_front();
  }
}

void FailoverRecord::request(const std::string& key, const CommandSample& s, const Now& now) {
  forget_old(now.steady);
  if (entries_.count(key)) return;
  Entry e;
  e.fingerprint = content_fingerprint(s);
  e.reply = make_reply(s, CommandResult::Failed, {});
  e.sample = s;
  e.arrived = now;
  for (const auto& [reply, at] : replies_)
    if (same_request(reply, e.reply)) e.answer = reply;
  if (const auto packet = command_packet(s))
    for (const auto& h : frames_)
      if (h.bus == s.bus && h.frame.address == s.address && h.frame.packet == *packet) e.heard = kHeardReason;
  add(key, std::move(e));
}

void FailoverRecord::relinquished(const std::string& key, std::uint64_t fingerprint, const CommandReplyData& reply,
                                  SteadyTime now) {
  forget_old(now);
  if (entries_.count(key)) return;
  Entry e;
  e.fingerprint = fingerprint;
  e.reply = reply;
  e.reply.has_value = false;
  e.reply.value = 0;
  e.reply.value_text.clear();
  e.arrived = Now{{}, now};
  e.heard = kHeardReason;
  add(key, std::move(e));
}

void FailoverRecord::peer_reply(const CommandReplyData& reply, SteadyTime now) {
  forget_old(now);
  bool matched = false;
  for (auto& [key, e] : entries_) {
    if (!same_request(e.reply, reply)) continue;
    matched = true;
    if (is_final(reply.result)) {
      if (!e.answer) e.answer = reply;
    } else if (!e.heard) {
      e.heard = kInProgressReason;
    }
  }
  if (matched || !is_final(reply.result)) return;
  replies_.emplace_back(reply, now);
  while (replies_.size() > limits_.max_requests) replies_.pop_front();
}

void FailoverRecord::heard(const std::string& bus, const codec::CanFrame& frame, SteadyTime now) {
  forget_old(now);
  const FrameRole role = frame_role(frame);
  if (role == FrameRole::Other) return;
  if (role == FrameRole::Get) {
    gets_.push_back({bus, frame.id, now});
    while (gets_.size() > limits_.max_frames) gets_.pop_front();
    return;
  }
  const auto id = *codec::parse_id(frame.id, true).id;
  if (frame.length > 0 && failover_detail::settable(id.packet)) {
    // The device's answer to a get heard before it, not a set.
    auto open =
        std::find_if(gets_.begin(), gets_.end(), [&](const OpenGet& g) { return g.bus == bus && g.id == frame.id; });
    if (open != gets_.end()) {
      gets_.erase(open);
      return;
    }
  }
  bool explained = false;
  for (auto& [key, e] : entries_) {
    if (e.answer || !e.sample || e.reply.bus != bus || e.reply.address != id.address) continue;
    if (command_packet(*e.sample) != id.packet) continue;
    explained = true;
    if (!e.heard) e.heard = kHeardReason;
  }
  // Kept for a request still to arrive only when none here explains it: the owner runs a
  // device's commands in order, so the frame is the earlier request's, not a later one's.
  if (explained) return;
  frames_.push_back({bus, CommandFrame{id.address, id.packet}, now});
  while (frames_.size() > limits_.max_frames) frames_.pop_front();
}

std::vector<FailoverRecord::Verdict> FailoverRecord::take_over(SteadyTime now) {
  forget_old(now);
  std::vector<Verdict> out;
  out.reserve(order_.size());
  for (const auto& key : order_) {
    auto it = entries_.find(key);
    if (it == entries_.end()) continue;
    Entry& e = it->second;
    Verdict v;
    v.key = key;
    v.fingerprint = e.fingerprint;
    v.reply = e.reply;
    if (e.answer) {
      v.action = Action::Answered;
      v.reply = *e.answer;
    } else if (e.sample && e.reply.kind == CommandKind::EngineStop) {
      // Heard or not, expired or not: a stop twice only ends cranking twice, a lost one is H4.
      v.action = Action::Run;
    } else if (e.heard || !e.sample) {
      v.action = Action::Unknown;
      v.reply.result = CommandResult::Failed;
      v.reply.reason = e.heard ? e.heard : kHeardReason;
    } else if (const auto until = deadline(e.sample->expires_at, e.arrived, lifetimes_); !until || *until < now) {
      v.action = Action::Expired;
      v.reply.result = CommandResult::Rejected;
      v.reply.reason = until ? "expired before it could be sent" : until.error();
    } else {
      v.action = Action::Run;
    }
    if (v.action == Action::Run) {
      v.sample = std::move(e.sample);
      v.arrived = e.arrived;
    }
    out.push_back(std::move(v));
  }
  entries_.clear();
  order_.clear();
  replies_.clear();
  frames_.clear();
  gets_.clear();
  return out;
}

}  // namespace pmu::service
