#include "pmuctl/verbs/energy_verb.hpp"

#include <CLI/CLI.hpp>
#include <algorithm>
#include <chrono>
#include <fastdds/dds/core/status/SubscriptionMatchedStatus.hpp>
#include <fastdds/dds/subscriber/SampleInfo.hpp>
#include <map>
#include <set>
#include <thread>
#include <tuple>

#include "pmu/idl/energyPubSubTypes.h"
#include "pmu/idl/guarded_type.hpp"
#include "pmu/idl/topics.hpp"
#include "pmuctl/verbs/energy_lines.hpp"
#include "pmuctl/call/exit_status.hpp"
#include "pmuctl/call/service_presence.hpp"
#include "pmuctl/call/state_settle.hpp"
#include "pmuctl/call/context_lease.hpp"

namespace pmu::tools {
// A namespace of its own: the unity builds put this file in one translation unit with the
// other verbs, whose helpers have the same names.
namespace energy_verb {
namespace {

using namespace eprosima::fastdds::dds;
using Clock = std::chrono::steady_clock;
using Key = std::tuple<std::string, std::string, std::uint16_t>;  // vehicle, bus, address or node

bool selected(const GlobalOptions& o, const std::string& vehicle, const std::string& bus) {
  return (!o.vehicle || *o.vehicle == vehicle) && (o.bus.empty() || o.bus == bus);
}
Key key_of(const pmu::v5::Energy& e) { return {e.vehicle().to_string(), e.bus().to_string(), e.address()}; }
Key key_of(const pmu::v5::BmsEnergy& e) { return {e.vehicle().to_string(), e.bus().to_string(), e.node()}; }
bool selected(const GlobalOptions& o, const pmu::v5::Energy& e) {
  return selected(o, e.vehicle().to_string(), e.bus().to_string()) && (!o.address || *o.address == e.address());
}
// --address names a PMU, so with it no battery is shown (as list and health do).
bool selected(const GlobalOptions& o, const pmu::v5::BmsEnergy& e) {
  return !o.address && selected(o, e.vehicle().to_string(), e.bus().to_string());
}

// The latest figures of each instance of one topic, and the writers heard from.
template <class Sample>
struct Latest {
  std::map<Key, Sample> by_key;
  std::map<InstanceHandle_t, Key> handles;
  std::set<InstanceHandle_t> writers;

  void take(const GlobalOptions& o, DataReader& reader) {
    Sample s;
    SampleInfo info;
    while (reader.take_next_sample(&s, &info) == ReturnCode_t::RETCODE_OK) {
      writers.insert(info.publication_handle);
      if (!info.valid_data) {
        // Disposed (a PMU that moved to another address): its figures are gone with it.
        if (auto it = handles.find(info.instance_handle);
            it != handles.end() && info.instance_state != ALIVE_INSTANCE_STATE) {
          by_key.erase(it->second);
          handles.erase(it);
        }
        continue;
      }
      if (!selected(o, s)) continue;
      by_key[key_of(s)] = s;
      handles[info.instance_handle] = key_of(s);
    }
  }
};

std::size_t matched(DataReader& reader) {
  SubscriptionMatchedStatus st;
  reader.get_subscription_matched_status(st);
  return static_cast<std::size_t>(std::max(st.current_count, 0));
}

int run(const GlobalOptions& o) {
  ContextLease lease(o, kPmuctlParticipant);
  pmu::dds::DdsContext& dds = *lease;
  DataReader& pmus = dds.reader(dds.topic(topics::kEnergy, TypeSupport(new idl::Guarded<pmu::v5::EnergyPubSubType>())),
                                qos_profiles::kState);
  DataReader& batteries =
      dds.reader(dds.topic(topics::kBmsEnergy, TypeSupport(new idl::Guarded<pmu::v5::BmsEnergyPubSubType>())),
                 qos_profiles::kState);
  const auto deadline = wait_end(o, 3.0);
  StateSettle settle(std::chrono::milliseconds(300));
  Latest<pmu::v5::Energy> pmu_figures;
  Latest<pmu::v5::BmsEnergy> bms_figures;
  while (Clock::now() < deadline) {
    pmu_figures.take(o, pmus);
    bms_figures.take(o, batteries);
    // Every service has a pmu/energy writer; only one that serves batteries or MPPTs has a
    // pmu/bms_energy writer, so those are expected once matched, not per service discovered.
    settle.observe(Clock::now(), writers_expected(dds, pmus, topics::kEnergy) + matched(batteries),
                   pmu_figures.writers.size() + bms_figures.writers.size());
    if (settle.settled(Clock::now())) break;
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  if (pmu_figures.by_key.empty() && bms_figures.by_key.empty()) {
    if (matched(pmus) == 0 && matched(batteries) == 0) return no_service(o, dds);
    if (pmu_figures.writers.empty() && bms_figures.writers.empty()) return nothing_heard(o);
    return fail(o, ExitStatus::BadUsage,
                std::string("no energy figures from ") +
                    (o.address ? "PMU " + std::to_string(*o.address) : std::string("any PMU or battery")) +
                    (o.bus.empty() ? std::string() : " on bus " + o.bus));
  }
  for (const auto& [key, e] : pmu_figures.by_key) print_energy(o, e);
  for (const auto& [key, e] : bms_figures.by_key) print_bms_energy(o, e);
  return 0;
}

}  // namespace
}  // namespace energy_verb

int run_energy(const GlobalOptions& o) { return energy_verb::run(o); }

std::unique_ptr<Verb> add_energy_verb(CLI::App& app) {
  return add_state_reading_verb(
      app, "energy", "Power per output, generator power, energy used and endurance of each battery", run_energy);
}

}  // namespace pmu::tools
