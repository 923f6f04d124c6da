#include "pmu/mavlink_params/param_server.hpp"

#include <algorithm>
#include <stdexcept>

#include "pmu/mavlink_params/status_text.hpp"

namespace pmu::mavlink_params {
namespace {

// A PARAM_VALUEs' bucket holds at most this many: a burst after a quiet while stays small.
constexpr double kBurst = 2;

std::string value_words(Setting s, std::uint32_t raw) { return baseline::value_text(s, raw); }

}  // namespace

service::CommandAction SetRequest::action() const {
  if (const auto p = baseline::parameter_of(param.setting)) return service::action::SetParameter{*p, raw};
  if (param.setting == Setting::Outputs) return service::action::SetOutputs{static_cast<std::uint8_t>(raw)};
  return service::action::SetGeneration{raw != 0};
}

ParamServer::ParamServer(ParamServerConfig config)
    : config_(config),
      devices_(config.pmu_count),
      urgent_(mavlink_params::param_count(config.pmu_count)),
      listed_(mavlink_params::param_count(config.pmu_count)) {
  if (config_.pmu_count < 1 || config_.pmu_count > kMaxPmus)
    throw std::invalid_argument("pmu-mavlink serves 1 to 9 PMUs through parameters, not " +
                                std::to_string(config_.pmu_count));
}

void ParamServer::set_device(std::size_t pmu, const baseline::Settings& settings) {
  if (pmu >= devices_.size()) return;
  for (std::size_t i = 0; i < kSettingCount; ++i) {
    const auto s = static_cast<Setting>(i);
    const auto& before = devices_[pmu][s];
    // A value a set of ours changed is sent by that set's answer, not a second time.
    const bool ours = std::any_of(pending_.begin(), pending_.end(), [&](const auto& entry) {
      return entry.second.param == ParamRef{pmu, s};
    });
    if (before && settings[s] && *before != *settings[s] && !ours) urgent_[param_index({pmu, s})] = true;
  }
  devices_[pmu] = settings;
}

void ParamServer::forget_device(std::size_t pmu) {
  if (pmu < devices_.size()) devices_[pmu] = {};
}

void ParamServer::grow(std::size_t pmu_count) {
  const std::size_t n = std::min(pmu_count, kMaxPmus);
  if (n <= config_.pmu_count) return;
  config_.pmu_count = n;
  devices_.resize(n);
  urgent_.resize(mavlink_params::param_count(n));
  listed_.resize(mavlink_params::param_count(n));
}

std::optional<std::uint32_t> ParamServer::value(ParamRef p) const { return devices_[p.pmu][p.setting]; }

mavlink::ParamValue ParamServer::param_value(ParamRef p, std::uint32_t raw) const {
  mavlink::ParamValue v;
  v.param_id = param_name(p);
  v.param_value = to_real32(p.setting, raw);
  v.param_type = mavlink::mav_param_type::kReal32;
  v.param_count = static_cast<std::uint16_t>(param_count());
  v.param_index = param_index(p);
  return v;
}

void ParamServer::add_text(Output& out, std::uint8_t severity, std::string_view text) {
  for (auto& t : status_text(severity, text, next_text_id_)) out.send.emplace_back(std::move(t));
  if (++next_text_id_ == 0) next_text_id_ = 1;
}

void ParamServer::on_request_list(Sender from, Time) {
  ++counters_.list_requests;
  const bool running = std::any_of(listed_.begin(), listed_.end(), [](bool b) { return b; });
  if (!running) list_senders_.clear();
  const bool served = std::find_if(list_senders_.begin(), list_senders_.end(), [&](const Sender& s) {
                        return s.system == from.system && s.component == from.component;
                      }) != list_senders_.end();
  if (running && (served || list_senders_.size() >= config_.max_list_senders)) {
    ++counters_.list_requests_merged;
    return;
  }
  list_senders_.push_back(from);
  // Marks only: what is still marked goes once, what went already goes again after the
  // cursor wraps. The pace is the same either way.
  std::fill(listed_.begin(), listed_.end(), true);
}

void ParamServer::on_request_read(Sender, const mavlink::ParamRequestRead& m, Time) {
  ++counters_.reads;
  const auto p = m.param_index >= 0 ? param_from_index(m.param_index, config_.pmu_count)
                                    : param_from_name(m.param_id, config_.pmu_count);
  if (!p || !value(*p)) {
    ++counters_.reads_unanswered;
    return;
  }
  urgent_[param_index(*p)] = true;
}

Output ParamServer::refuse(ParamRef p, std::string_view why) {
  ++counters_.sets_refused;
  Output out;
  const auto now_value = value(p);
  if (now_value) out.send.emplace_back(param_value(p, *now_value));
  add_text(out, mavlink::mav_severity::kWarning, param_name(p) + " not set: " + std::string(why));
  return out;
}

Output ParamServer::on_param_set(Sender, const mavlink::ParamSet& m, Time now) {
  ++counters_.sets;
  const auto p = param_from_name(m.param_id, config_.pmu_count);
  if (!p) {
    ++counters_.sets_unknown_name;
    return {};
  }
  const auto current = value(*p);
  if (!current) return refuse(*p, "PMU" + std::to_string(p->pmu + 1) + "'s settings are not known yet");
  if (m.param_type != mavlink::mav_param_type::kReal32)
    return refuse(*p, "its type is REAL32 (9), not " + std::to_string(m.param_type));
  const auto raw = from_real32(p->setting, m.param_value);
  if (!raw) return refuse(*p, raw.error());
  for (const auto& [tag, set] : pending_) {
    if (!(set.param == *p)) continue;
    if (set.raw == *raw) {
      ++counters_.sets_merged;
      return {};
    }
    return refuse(*p, "a set to " + value_words(p->setting, set.raw) + " is in progress");
  }
  if (*raw == *current) {
    Output out;
    out.send.emplace_back(param_value(*p, *current));
    return out;
  }
  if (!spec_of(p->setting).writable) return refuse(*p, "read-only here (pmuctl config set)");
  if (pending_.size() >= config_.max_pending_sets) return refuse(*p, "too many sets in progress");

  SetRequest request{next_tag_++, *p, *raw, false};
  service::CommandRequest judged;
  judged.action = request.action();
  // Unknown unit values at their worst (DeviceUse's defaults), as pmuctl's apply does.
  if (const auto rule = service::confirm_rule_for(judged)) {
    if (!config_.confirm[static_cast<std::size_t>(*rule)])
      return refuse(*p, "rule " + std::string(service::to_string(*rule)) + ": it " +
                            std::string(service::rule_why(*rule)) + "; pmu-mavlink --confirm " +
                            std::string(service::to_string(*rule)) + " allows it");
    request.confirm = true;
  }
  ++counters_.sets_sent;
  pending_.emplace(request.tag, PendingSet{*p, *raw, now + config_.set_timeout});
  Output out;
  out.request = request;
  return out;
}

Output ParamServer::on_set_reply(std::uint64_t tag, service::CommandResult result, std::string_view reason) {
  if (!service::is_final(result)) return {};
  const auto it = pending_.find(tag);
  if (it == pending_.end()) {
    ++counters_.replies_unmatched;
    return {};
  }
  const PendingSet set = it->second;
  pending_.erase(it);
  Output out;
  if (result == service::CommandResult::Completed) {
    // COMPLETED: the service read the device back and it holds the value (interface.md 2.1).
    devices_[set.param.pmu][set.param.setting] = set.raw;
    out.send.emplace_back(param_value(set.param, set.raw));
    return out;
  }
  if (const auto v = value(set.param)) out.send.emplace_back(param_value(set.param, *v));
  add_text(out, mavlink::mav_severity::kWarning,
           param_name(set.param) + " " + std::string(service::to_string(result)) + ": " + std::string(reason));
  return out;
}

std::optional<std::size_t> ParamServer::next_marked() const {
  for (std::size_t i = 0; i < urgent_.size(); ++i)
    if (urgent_[i]) return i;
  for (std::size_t k = 0; k < listed_.size(); ++k) {
    const std::size_t i = (cursor_ + k) % listed_.size();
    if (listed_[i]) return i;
  }
  return std::nullopt;
}

Output ParamServer::poll(Time now) {
  Output out;
  for (auto it = pending_.begin(); it != pending_.end();) {
    if (now < it->second.deadline) {
      ++it;
      continue;
    }
    ++counters_.sets_timed_out;
    const auto p = it->second.param;
    it = pending_.erase(it);
    if (const auto v = value(p)) out.send.emplace_back(param_value(p, *v));
    add_text(out, mavlink::mav_severity::kWarning,
             param_name(p) + " not confirmed: no reply from the service within " +
                 std::to_string(config_.set_timeout.count()) + " ms");
  }
  if (last_refill_)
    tokens_ = std::min(kBurst, tokens_ + std::chrono::duration<double>(now - *last_refill_).count() *
                                             config_.messages_per_second);
  last_refill_ = now;
  while (tokens_ >= 1) {
    const auto i = next_marked();
    if (!i) break;
    const bool from_list = !urgent_[*i];
    urgent_[*i] = false;
    listed_[*i] = false;  // a read answers for the list too
    if (from_list) cursor_ = (*i + 1) % listed_.size();
    const auto p = *param_from_index(static_cast<std::int64_t>(*i), config_.pmu_count);
    const auto v = value(p);
    if (!v) {  // not known: nothing to say, and it costs the link nothing
      ++counters_.values_skipped;
      continue;
    }
    tokens_ -= 1;
    ++counters_.values_sent;
    out.send.emplace_back(param_value(p, *v));
  }
  return out;
}

std::optional<Time> ParamServer::next_due() const {
  std::optional<Time> due;
  for (const auto& [tag, set] : pending_)
    if (!due || set.deadline < *due) due = set.deadline;
  if (next_marked() && last_refill_) {
    const auto wait = std::chrono::duration<double>((1 - std::min(tokens_, 1.0)) / config_.messages_per_second);
    const Time t = *last_refill_ + std::chrono::duration_cast<std::chrono::steady_clock::duration>(wait);
    if (!due || t < *due) due = t;
  } else if (next_marked()) {
    due = Time{};  // never polled: at once
  }
  return due;
}

}  // namespace pmu::mavlink_params
