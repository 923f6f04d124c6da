#include "pmuctl/verbs/preflight_verb.hpp"

#include <CLI/CLI.hpp>
#include <chrono>
#include <cstdio>
#include <fastdds/dds/core/status/SubscriptionMatchedStatus.hpp>
#include <fastdds/dds/subscriber/SampleInfo.hpp>
#include <map>
#include <nlohmann/json.hpp>
#include <set>
#include <thread>
#include <vector>

#include "pmu/dds/contract_names.hpp"
#include "pmu/idl/alarmsPubSubTypes.h"
#include "pmu/idl/guarded_type.hpp"
#include "pmu/idl/topics.hpp"
#include "pmuctl/verbs/alarm_names.hpp"
#include "pmuctl/call/exit_status.hpp"
#include "pmuctl/call/service_presence.hpp"
#include "pmuctl/call/state_settle.hpp"
#include "pmuctl/call/context_lease.hpp"
#include "pmuctl/verbs/role_verbs.hpp"
#include "pmuctl/view/role_view.hpp"

namespace pmu::tools {
namespace {

using namespace eprosima::fastdds::dds;
using Clock = std::chrono::steady_clock;

const char* level_name(pmu::v5::ReadinessLevel l) {
  switch (l) {
    case pmu::v5::LEVEL_WARNING: return "WARNING";
    case pmu::v5::LEVEL_NOT_READY: return "NOT_READY";
    case pmu::v5::LEVEL_READY: break;
  }
  return "READY";
}

// A vehicle's readiness as its service says it, or none (a pair with no bus owner writes no
// state), and what its hot-standby pair is short of (role_view.hpp): a pair with no owner, two
// owners, a silent instance or an alarm is NOT READY whatever the readiness says (docs/safety.md
// H6). `pair`: the vehicle's instances seen on pmu/role, empty when it runs alone.
void print(const GlobalOptions& o, const std::string& vehicle, const pmu::v5::Readiness* r,
           const std::vector<SeenInstance>& pair) {
  const auto problems = pair.empty() ? std::vector<std::string>() : pair_problems(pair);
  const bool ready = r && r->ready() && problems.empty();
  const std::uint32_t total = (r ? r->reasons_total() : 0) + static_cast<std::uint32_t>(problems.size());
  if (o.json) {
    nlohmann::ordered_json reasons = nlohmann::ordered_json::array();
    if (r)
      for (const auto& x : r->reasons())
        reasons.push_back({{"code", x.code().to_string()},
                           {"severity", x.severity() == pmu::v5::SEVERITY_CRITICAL ? "critical" : "warning"},
                           {"bus", x.bus().to_string()},
                           {"kind", alarm_source_name(x.kind())},
                           {"device", x.device()},
                           {"message", x.message().to_string()},
                           {"description", x.description().to_string()}});
    nlohmann::ordered_json j{
        {"topic", "readiness"},
        {"vehicle", vehicle},
        {"ready", ready},
        {"level", r && problems.empty() ? level_name(r->level()) : "NOT_READY"},
        {"since", r ? nlohmann::ordered_json(static_cast<double>(r->since()) / 1e9) : nlohmann::ordered_json(nullptr)},
        {"reasons", reasons},
        {"reasons_total", r ? r->reasons_total() : 0}};
    if (!pair.empty()) {
      nlohmann::ordered_json instances = nlohmann::ordered_json::array();
      for (const auto& s : pair) instances.push_back(role_json(s, pmu::dds::contract_major())["values"]);
      j["pair"] = {{"instances", instances}, {"problems", problems}};
    }
    j["contract"] = pmu::dds::contract_major();
    std::printf("%s\n", j.dump(-1, ' ', false, nlohmann::json::error_handler_t::replace).c_str());
    return;
  }
  const char* verdict =
      !ready ? "NOT READY" : (r->level() == pmu::v5::LEVEL_WARNING ? "READY, with warnings" : "READY");
  std::printf("%s: %s", vehicle.empty() ? "(unnamed vehicle)" : vehicle.c_str(), verdict);
  std::printf(total ? " (%u reason%s)\n" : "\n", total, total == 1 ? "" : "s");
  for (const auto& p : problems)
    std::printf("  %-8s %-24s %-14s %s\n           %s\n", "CRITICAL", "hot_standby", "pair", p.c_str(),
                "one instance of the pair must own the bus, the other stand by, neither raise an alarm "
                "(pmuctl list shows the pair)");
  if (!r) {
    std::printf("  %-8s %-24s %-14s %s\n", "CRITICAL", "no_readiness", "-", "no pmu/readiness from this vehicle");
    return;
  }
  for (const auto& x : r->reasons()) {
    std::string where = x.bus().to_string();
    if (x.kind() != pmu::v5::SOURCE_BUS)
      where += "/" + std::string(x.kind() == pmu::v5::SOURCE_PMU ? "" : alarm_source_name(x.kind())) +
               std::to_string(x.device());
    std::printf("  %-8s %-24s %-14s %s\n           %s\n",
                x.severity() == pmu::v5::SEVERITY_CRITICAL ? "CRITICAL" : "WARNING", x.code().c_str(), where.c_str(),
                x.message().c_str(), x.description().c_str());
  }
  if (r->reasons_total() > r->reasons().size())
    std::printf("  ... and %zu more\n", static_cast<std::size_t>(r->reasons_total() - r->reasons().size()));
}

}  // namespace

int run_preflight(const GlobalOptions& o) {
  ContextLease lease(o, kPmuctlParticipant);
  pmu::dds::DdsContext& dds = *lease;
  DataReader& reader =
      dds.reader(dds.topic(topics::kReadiness, TypeSupport(new idl::Guarded<pmu::v5::ReadinessPubSubType>())),
                 qos_profiles::kState);
  RoleCollector roles(o, dds);
  const auto deadline = wait_end(o, 3.0);
  StateSettle settle(std::chrono::milliseconds(300));
  std::map<std::string, pmu::v5::Readiness> latest;
  std::set<InstanceHandle_t> writers;
  while (Clock::now() < deadline) {
    pmu::v5::Readiness r;
    SampleInfo info;
    while (reader.take_next_sample(&r, &info) == ReturnCode_t::RETCODE_OK) {
      writers.insert(info.publication_handle);
      if (info.valid_data && (!o.vehicle || *o.vehicle == r.vehicle().to_string())) latest[r.vehicle().to_string()] = r;
    }
    settle.observe(Clock::now(), writers_expected(dds, reader, topics::kReadiness), writers.size());
    if (settle.settled(Clock::now())) break;
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  roles.wait_for_peers(deadline);
  std::map<std::string, std::vector<SeenInstance>> pairs;
  for (auto& s : roles.seen()) pairs[s.vehicle].push_back(std::move(s));
  if (latest.empty() && pairs.empty()) {
    SubscriptionMatchedStatus st;
    reader.get_subscription_matched_status(st);
    if (st.current_count == 0) return no_service(o, dds);
    if (writers.empty()) return nothing_heard(o);
    return fail(o, ExitStatus::NoAnswer,
                "no readiness from " + (o.vehicle ? vehicle_text(*o.vehicle) : std::string("any vehicle")) +
                    " within the timeout");
  }
  std::set<std::string> vehicles;
  for (const auto& [vehicle, r] : latest) vehicles.insert(vehicle);
  for (const auto& [vehicle, pair] : pairs) vehicles.insert(vehicle);
  bool ready = true;
  for (const auto& vehicle : vehicles) {
    const auto r = latest.find(vehicle);
    const auto p = pairs.find(vehicle);
    const auto& pair = p == pairs.end() ? std::vector<SeenInstance>() : p->second;
    print(o, vehicle, r == latest.end() ? nullptr : &r->second, pair);
    ready = ready && r != latest.end() && r->second.ready() && (pair.empty() || pair_problems(pair).empty());
  }
  return static_cast<int>(ready ? ExitStatus::Ok : ExitStatus::NotDone);
}

std::unique_ptr<Verb> add_preflight_verb(CLI::App& app) {
  return add_state_reading_verb(app, "preflight",
                                "Whether the vehicle may fly, and every reason it may not (exit 0 ready, 1 not)",
                                run_preflight);
}

}  // namespace pmu::tools
