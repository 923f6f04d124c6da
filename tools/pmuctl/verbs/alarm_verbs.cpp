#include "pmuctl/verbs/alarm_verbs.hpp"

#include <CLI/CLI.hpp>
#include <chrono>
#include <cstdio>
#include <ctime>
#include <fastdds/dds/core/status/SubscriptionMatchedStatus.hpp>
#include <fastdds/dds/subscriber/SampleInfo.hpp>
#include <algorithm>
#include <map>
#include <set>
#include <nlohmann/json.hpp>
#include <thread>
#include <tuple>

#include "pmu/dds/contract_names.hpp"
#include "pmu/idl/alarmsPubSubTypes.h"
#include "pmu/idl/alarms.h"
#include "pmu/idl/guarded_type.hpp"
#include "pmu/idl/topics.hpp"
#include "pmuctl/verbs/alarm_sample.hpp"
#include "pmuctl/call/exit_status.hpp"
#include "pmuctl/call/service_presence.hpp"
#include "pmuctl/call/context_lease.hpp"
#include "pmuctl/verbs/command_verbs.hpp"

namespace pmu::tools {
namespace {

using namespace eprosima::fastdds::dds;
using Clock = std::chrono::steady_clock;

// One alarm instance: the sample's keys, the kind as the contract orders it (PMU, battery,
// MPPT, bus), which is the order the lines come in.
using AlarmKey = std::tuple<std::string, std::string, int, std::uint16_t, std::string>;
AlarmKey key_of(const pmu::v5::Alarm& a) {
  return {a.vehicle().to_string(), a.bus().to_string(), static_cast<int>(a.kind()), a.device(), a.code().to_string()};
}

std::string utc(std::uint64_t ns) {
  const std::time_t t = static_cast<std::time_t>(ns / 1000000000ull);
  std::tm tm{};
  gmtime_r(&t, &tm);
  char buf[32];
  std::strftime(buf, sizeof buf, "%Y-%m-%dT%H:%M:%SZ", &tm);
  return buf;
}

void print(const GlobalOptions& o, const AlarmEntry& a) {
  if (o.json) {
    std::printf("%s\n", alarm_json(a, pmu::dds::contract_major())
                            .dump(-1, ' ', false, nlohmann::ordered_json::error_handler_t::replace)
                            .c_str());
    return;
  }
  std::printf("%-18s %-8s %-22s %-28s since %s  %s\n", alarm_source(a).c_str(), a.critical ? "CRITICAL" : "WARNING",
              to_string(a.state), a.code.c_str(), utc(a.since).c_str(), a.message.c_str());
}

}  // namespace

int run_alarms(const GlobalOptions& o) {
  ContextLease lease(o, kPmuctlParticipant);
  pmu::dds::DdsContext& dds = *lease;
  DataReader& reader = dds.reader(dds.topic(topics::kAlarms, TypeSupport(new idl::Guarded<pmu::v5::AlarmPubSubType>())),
                                  qos_profiles::kAlarms);
  // A service with no alarm sends nothing on pmu/alarms, nor does one that is dead but still
  // matched (a participant that knew it holds it until its lease ends): its pmu/readiness,
  // which a live service sends a reader at once, tells them apart. No all-clear is said
  // unless a service answered (docs/safety.md H6).
  DataReader& readiness =
      dds.reader(dds.topic(topics::kReadiness, TypeSupport(new idl::Guarded<pmu::v5::ReadinessPubSubType>())),
                 qos_profiles::kState);
  std::set<InstanceHandle_t> answered;  // readiness writers heard
  const auto deadline = wait_end(o, 3.0);
  // A service with no alarm that ever left NORMAL has nothing in its history, so the wait
  // cannot end on a sample: it ends once every service discovered has matched and nothing
  // new came for the quiet time (a matched writer sends what it holds at once).
  constexpr auto kQuiet = std::chrono::milliseconds(500);
  std::map<AlarmKey, AlarmEntry> latest;
  auto last_change = Clock::now();
  std::int32_t matched = 0;
  std::size_t coming = 0;
  while (Clock::now() < deadline) {
    pmu::v5::Alarm a;
    SampleInfo info;
    while (reader.take_next_sample(&a, &info) == ReturnCode_t::RETCODE_OK) {
      last_change = Clock::now();
      if (!info.valid_data) continue;
      const AlarmEntry e = alarm_entry_of(a);
      if (selected(o, e)) latest[key_of(a)] = e;
    }
    pmu::v5::Readiness r;
    while (readiness.take_next_sample(&r, &info) == ReturnCode_t::RETCODE_OK)
      if (answered.insert(info.publication_handle).second) last_change = Clock::now();
    SubscriptionMatchedStatus st;
    reader.get_subscription_matched_status(st);
    SubscriptionMatchedStatus ready_st;
    readiness.get_subscription_matched_status(ready_st);
    const auto now_coming =
        dds.remote_writers().participants_without_writer(pmu::dds::kServiceParticipantName, topics::kAlarms);
    if (st.current_count != matched || now_coming != coming) last_change = Clock::now();
    matched = st.current_count;
    coming = now_coming;
    const bool all_answered = answered.size() >= static_cast<std::size_t>(std::max(ready_st.current_count, 1));
    if (matched > 0 && coming == 0 && all_answered && Clock::now() - last_change >= kQuiet) break;
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  if (matched == 0) return no_service(o, dds);
  if (answered.empty()) return nothing_heard(o);
  std::size_t shown = 0;
  for (const auto& [key, a] : latest) {
    if (a.state == AlarmStatus::Normal) continue;
    print(o, a);
    ++shown;
  }
  if (shown == 0 && !o.json) std::fprintf(stderr, "no alarm is active or waiting for acknowledgement\n");
  return 0;
}

namespace {

// alarms, and alarms ack CODE [--kind KIND].
class AlarmVerbs : public Verb {
 public:
  explicit AlarmVerbs(CLI::App& app) {
    alarms_ = app.add_subcommand("alarms", "Alarms that are active or wait for acknowledgement");
    ack_ = alarms_->add_subcommand(
        "ack", "Acknowledge an alarm (a PMU's by default, chosen as for commands; exit 0 COMPLETED, 1 not)");
    ack_->add_option("code", code_, "The alarm's code, e.g. thermal_shutdown")->required();
    ack_->add_option("--kind", kind_,
                     "Whose alarm: pmu (default), battery or mppt (--address: the node or device id), bus "
                     "(--bus)");
  }
  bool chosen() const override { return alarms_->parsed(); }
  bool reads_state() const override { return !*ack_; }
  int run(GlobalOptions& g) override { return *ack_ ? run_alarm_ack(g, code_, kind_) : run_alarms(g); }

 private:
  CLI::App* alarms_;
  CLI::App* ack_;
  std::string code_, kind_ = "pmu";
};

}  // namespace

std::unique_ptr<Verb> add_alarm_verbs(CLI::App& app) { return std::make_unique<AlarmVerbs>(app); }

}  // namespace pmu::tools
