#include "pmu/mavlink_commands/command_handler.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <stdexcept>
#include <string>

#include "pmu/codec/messages.hpp"
#include "pmu/mavlink_params/param_table.hpp"
#include "pmu/mavlink_params/status_text.hpp"

namespace pmu::mavlink_commands {
namespace {

namespace result = mavlink::mav_result;
namespace cmd = mavlink::mav_cmd;
using service::CommandResult;

// PREFLIGHT_REBOOT_SHUTDOWN param3, REBOOT_SHUTDOWN_ACTION.
constexpr float kRebootComponent = 1;

bool whole(float v, long lo, long hi) {
  return std::isfinite(v) && v == std::round(v) && v >= static_cast<float>(lo) && v <= static_cast<float>(hi);
}

std::uint8_t ack_result(CommandResult r) {
  switch (r) {
    case CommandResult::Completed: return result::kAccepted;
    case CommandResult::Rejected:
    case CommandResult::Denied: return result::kDenied;
    case CommandResult::Unsupported: return result::kUnsupported;
    case CommandResult::Timeout:
    case CommandResult::Failed: return result::kFailed;
    case CommandResult::InProgress: return result::kInProgress;
  }
  return result::kFailed;
}

// What a COMMAND_LONG asks of the service, or of the program, or why it is answered here.
struct Meaning {
  std::optional<service::CommandAction> action;
  std::size_t pmu = 0;
  std::uint8_t result = result::kAccepted;  // when answered here
  std::string why;
};

Meaning refused(std::uint8_t r, std::string why) {
  Meaning m;
  m.result = r;
  m.why = std::move(why);
  return m;
}

Meaning interpret(const mavlink::CommandLong& c, const CommandConfig& config) {
  const auto& p = c.param;
  const auto pmu_of = [&](Meaning m) {
    if (!whole(p[6], 0, static_cast<long>(config.pmu_count)))
      return refused(result::kDenied,
                     "param7 names no PMU of this bridge (0 or 1.." + std::to_string(config.pmu_count) + ")");
    m.pmu = p[6] == 0 ? 0 : static_cast<std::size_t>(p[6]) - 1;
    return m;
  };
  Meaning m;
  switch (c.command) {
    case cmd::kDoEngineControl:
      if (p[0] == 0) {
        m.action = service::action::EngineStop{};
        return pmu_of(m);
      }
      if (p[0] != 1) return refused(result::kDenied, "engine control: param1 is 1 (start) or 0 (stop)");
      if (p[1] != 0) return refused(result::kDenied, "engine start: the PMU has no cold start (param2)");
      if (p[2] != 0) return refused(result::kDenied, "engine start: no height delay here (param3)");
      m.action = service::action::EngineStart{};
      return pmu_of(m);
    case cmd::kDoSetRelay: {
      if (!whole(p[0], 0, kGenerationRelay) || !(p[1] == 0 || p[1] == 1))
        return refused(result::kDenied, "relay: instance 0..4 (outputs, then generation), setting 0 or 1");
      const bool on = p[1] == 1;
      const auto instance = static_cast<int>(p[0]);
      if (instance == kGenerationRelay) {
        m.action = service::action::SetGeneration{on};
      } else {
        const auto bit = static_cast<std::uint8_t>(1U << instance);
        if (on)
          m.action = service::action::EnableOutputs{bit};
        else
          m.action = service::action::DisableOutputs{bit};
      }
      return pmu_of(m);
    }
    case cmd::kPreflightRebootShutdown:
      if (p[2] != kRebootComponent)
        return refused(result::kUnsupported, "reboot: only param3 1, reboot this component");
      if (p[3] != 0 && p[3] != config.own_component)
        return refused(result::kUnsupported, "reboot: param4 names another component");
      m.action = service::action::Reset{};
      return pmu_of(m);
    default: return refused(result::kUnsupported, "");
  }
}

}  // namespace

std::uint8_t start_progress(std::string_view reason) noexcept {
  const std::string text(reason.substr(0, 128));
  const auto colon = text.find(": ");
  double done = 0, of = 0;
  if (colon == std::string::npos || std::sscanf(text.c_str() + colon + 2, "%lf s of up to %lf s", &done, &of) != 2 ||
      !(of > 0) || !(done >= 0))
    return mavlink::not_provided::kProgress;
  return static_cast<std::uint8_t>(std::min(99.0, done / of * 100));
}

CommandHandler::CommandHandler(CommandConfig config) : config_(std::move(config)) {
  if (config_.pmu_count < 1 || config_.pmu_count > mavlink_params::kMaxPmus)
    throw std::invalid_argument("pmu-mavlink serves 1 to 9 PMUs, not " + std::to_string(config_.pmu_count));
}

CommandHandler::Entry* CommandHandler::find(Sender from, const mavlink::CommandLong& m) {
  for (auto it = entries_.rbegin(); it != entries_.rend(); ++it)
    if (it->from.system == from.system && it->from.component == from.component && it->command == m.command &&
        std::memcmp(it->param.data(), m.param.data(), sizeof m.param) == 0)
      return &*it;
  return nullptr;
}

CommandHandler::Entry* CommandHandler::find(std::uint64_t tag) {
  for (auto& e : entries_)
    if (!e.final && e.tag == tag) return &e;
  return nullptr;
}

mavlink::CommandAck CommandHandler::ack(const Entry& e) const {
  mavlink::CommandAck a;
  a.command = e.command;
  a.result = e.result;
  a.progress = e.result == result::kInProgress ? e.progress : 0;
  a.target_system = e.from.system;
  a.target_component = e.from.component;
  return a;
}

std::size_t CommandHandler::running() const {
  return static_cast<std::size_t>(
      std::count_if(entries_.begin(), entries_.end(), [](const Entry& e) { return !e.final && !e.stop; }));
}

void CommandHandler::remember(Entry e) {
  entries_.push_back(std::move(e));
  // Answered commands beyond the bound go, oldest first; running ones stay until answered.
  std::size_t answered =
      static_cast<std::size_t>(std::count_if(entries_.begin(), entries_.end(), [](const Entry& x) { return x.final; }));
  for (auto it = entries_.begin(); answered > config_.max_remembered && it != entries_.end();) {
    if (it->final) {
      it = entries_.erase(it);
      --answered;
    } else {
      ++it;
    }
  }
}

Output CommandHandler::answer_here(Sender from, const mavlink::CommandLong& m, std::uint8_t r, std::string_view why,
                                   Time now) {
  Entry e;
  e.from = from;
  e.command = m.command;
  e.param = m.param;
  e.final = true;
  e.result = r;
  e.answered_at = now;
  Output out;
  out.acks.push_back(ack(e));
  if (!why.empty()) out.texts = mavlink_params::status_text(mavlink::mav_severity::kWarning, why, next_text_id_++);
  if (next_text_id_ == 0) next_text_id_ = 1;
  remember(std::move(e));
  return out;
}

Output CommandHandler::on_command_long(Sender from, const mavlink::CommandLong& m, Time now) {
  ++counters_.received;
  const Meaning meaning = interpret(m, config_);
  const bool stop = meaning.action && std::holds_alternative<service::action::EngineStop>(*meaning.action);
  if (Entry* first = find(from, m)) {
    // A stop that already went out and was answered is sent again: the engine may crank
    // again since (docs/safety.md H4). Anything else that repeats is the first (H8).
    const bool repeat = !first->final || (!first->stop && m.confirmation > 0 &&
                                          now - first->answered_at <= config_.retransmission_window);
    if (repeat) {
      ++counters_.retransmissions;
      Output out;
      out.acks.push_back(ack(*first));
      return out;
    }
  }
  if (!meaning.action) {
    if (meaning.result == result::kUnsupported) ++counters_.unsupported;
    if (meaning.result == result::kDenied) ++counters_.denied;
    return answer_here(from, m, meaning.result, meaning.why, now);
  }
  bool confirm = false;
  if (!stop) {
    if (running() >= config_.max_pending) {
      ++counters_.flood_rejected;
      return answer_here(from, m, result::kTemporarilyRejected, "", now);
    }
    service::CommandRequest judged;
    judged.action = *meaning.action;
    if (const auto rule = service::confirm_rule_for(judged)) {
      const auto name = std::string(service::to_string(*rule));
      if (!config_.confirm[static_cast<std::size_t>(*rule)]) {
        ++counters_.denied;
        return answer_here(from, m, result::kDenied,
                           "rule " + name + ": it " + std::string(service::rule_why(*rule)) +
                               "; pmu-mavlink --confirm " + name + " allows it",
                           now);
      }
      confirm = true;
    }
  }
  const bool start = std::holds_alternative<service::action::EngineStart>(*meaning.action);
  Entry e;
  e.from = from;
  e.command = m.command;
  e.param = m.param;
  e.tag = next_tag_++;
  e.stop = stop;
  e.start = start;
  e.last_ack = now;
  e.result = result::kInProgress;
  e.progress = 0;
  e.deadline = now + (start ? config_.start_timeout : config_.reply_timeout);
  Output out;
  // An engine start takes seconds: the ground station hears at once that it runs, and waits.
  if (start) out.acks.push_back(ack(e));
  out.command = ServiceCommand{*e.tag, meaning.pmu, *meaning.action, confirm};
  ++counters_.sent;
  if (stop) ++counters_.stops;
  remember(std::move(e));
  return out;
}

Output CommandHandler::on_reply(std::uint64_t tag, CommandResult r, std::string_view reason, Time now) {
  Entry* e = find(tag);
  if (!e) {
    ++counters_.replies_unmatched;
    return {};
  }
  Output out;
  if (!service::is_final(r)) {
    e->progress = start_progress(reason);
    e->last_ack = now;
    out.acks.push_back(ack(*e));
    return out;
  }
  e->final = true;
  e->tag.reset();
  e->result = ack_result(r);
  e->answered_at = now;
  out.acks.push_back(ack(*e));
  if (r != CommandResult::Completed) {
    out.texts =
        mavlink_params::status_text(mavlink::mav_severity::kWarning,
                                    std::string(service::to_string(r)) + ": " + std::string(reason), next_text_id_++);
    if (next_text_id_ == 0) next_text_id_ = 1;
  }
  return out;
}

Output CommandHandler::poll(Time now) {
  Output out;
  for (auto& e : entries_) {
    if (!e.final && e.start && now < e.deadline && now - e.last_ack >= config_.in_progress_every) {
      e.last_ack = now;
      out.acks.push_back(ack(e));
    }
    if (e.final || now < e.deadline) continue;
    ++counters_.timed_out;
    e.final = true;
    e.tag.reset();
    e.result = result::kFailed;
    e.answered_at = now;
    out.acks.push_back(ack(e));
    for (auto& t : mavlink_params::status_text(mavlink::mav_severity::kWarning,
                                               "command " + std::to_string(e.command) + ": no reply from the service",
                                               next_text_id_++))
      out.texts.push_back(std::move(t));
    if (next_text_id_ == 0) next_text_id_ = 1;
  }
  entries_.erase(
      std::remove_if(entries_.begin(), entries_.end(),
                     [&](const Entry& e) { return e.final && now - e.answered_at > config_.retransmission_window; }),
      entries_.end());
  return out;
}

}  // namespace pmu::mavlink_commands
