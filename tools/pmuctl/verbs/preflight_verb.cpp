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

#include "pmu/dds/contract_names.hpp"
#include "pmu/idl/alarmsPubSubTypes.h"
#include "pmu/idl/guarded_type.hpp"
#include "pmu/idl/topics.hpp"
#include "pmuctl/verbs/alarm_names.hpp"
#include "pmuctl/call/exit_status.hpp"
#include "pmuctl/call/service_presence.hpp"
#include "pmuctl/call/state_settle.hpp"
#include "pmuctl/call/context_lease.hpp"

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

void print(const GlobalOptions& o, const pmu::v5::Readiness& r) {
  const std::string vehicle = r.vehicle().to_string();
  if (o.json) {
    nlohmann::json reasons = nlohmann::json::array();
    for (const auto& x : r.reasons())
      reasons.push_back({{"code", x.code().to_string()},
                         {"severity", x.severity() == pmu::v5::SEVERITY_CRITICAL ? "critical" : "warning"},
                         {"bus", x.bus().to_string()},
                         {"kind", alarm_source_name(x.kind())},
                         {"device", x.device()},
                         {"message", x.message().to_string()},
                         {"description", x.description().to_string()}});
    nlohmann::json j{{"topic", "readiness"},
                     {"vehicle", vehicle},
                     {"ready", r.ready()},
                     {"level", level_name(r.level())},
                     {"since", static_cast<double>(r.since()) / 1e9},
                     {"reasons", reasons},
                     {"reasons_total", r.reasons_total()},
                     {"contract", pmu::dds::contract_major()}};
    std::printf("%s\n", j.dump(-1, ' ', false, nlohmann::json::error_handler_t::replace).c_str());
    return;
  }
  std::printf("%s: %s", vehicle.empty() ? "(unnamed vehicle)" : vehicle.c_str(),
              r.ready() ? (r.level() == pmu::v5::LEVEL_WARNING ? "READY, with warnings" : "READY") : "NOT READY");
  std::printf(r.reasons_total() ? " (%u reason%s)\n" : "\n", r.reasons_total(), r.reasons_total() == 1 ? "" : "s");
  for (const auto& x : r.reasons()) {
    std::string where = x.bus().to_string();
    if (x.kind() != pmu::v5::SOURCE_BUS)
      where += "/" + std::string(x.kind() == pmu::v5::SOURCE_PMU ? "" : alarm_source_name(x.kind())) +
               std::to_string(x.device());
    std::printf("  %-8s %-24s %-14s %s\n           %s\n",
                x.severity() == pmu::v5::SEVERITY_CRITICAL ? "CRITICAL" : "WARNING", x.code().c_str(), where.c_str(),
                x.message().c_str(), x.description().c_str());
  }
  if (r.reasons_total() > r.reasons().size())
    std::printf("  ... and %zu more\n", static_cast<std::size_t>(r.reasons_total() - r.reasons().size()));
}

}  // namespace

int run_preflight(const GlobalOptions& o) {
  ContextLease lease(o, kPmuctlParticipant);
  pmu::dds::DdsContext& dds = *lease;
  DataReader& reader =
      dds.reader(dds.topic(topics::kReadiness, TypeSupport(new idl::Guarded<pmu::v5::ReadinessPubSubType>())),
                 qos_profiles::kState);
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
  if (latest.empty()) {
    SubscriptionMatchedStatus st;
    reader.get_subscription_matched_status(st);
    if (st.current_count == 0) return no_service(o, dds);
    if (writers.empty()) return nothing_heard(o);
    return fail(o, ExitStatus::NoAnswer,
                "no readiness from " + (o.vehicle ? vehicle_text(*o.vehicle) : std::string("any vehicle")) +
                    " within the timeout");
  }
  bool ready = true;
  for (const auto& [vehicle, r] : latest) {
    print(o, r);
    ready = ready && r.ready();
  }
  return static_cast<int>(ready ? ExitStatus::Ok : ExitStatus::NotDone);
}

std::unique_ptr<Verb> add_preflight_verb(CLI::App& app) {
  return add_state_reading_verb(app, "preflight",
                                "Whether the vehicle may fly, and every reason it may not (exit 0 ready, 1 not)",
                                run_preflight);
}

}  // namespace pmu::tools
