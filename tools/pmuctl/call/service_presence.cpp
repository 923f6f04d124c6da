#include "pmuctl/call/service_presence.hpp"

#include <algorithm>
#include <fastdds/dds/core/status/SubscriptionMatchedStatus.hpp>

#include "pmu/dds/contract_names.hpp"
#include "pmu/idl/topics.hpp"
#include "pmuctl/call/exit_status.hpp"

namespace pmu::tools {

namespace {

// A service's writers sit in its vehicle's partition, or in none for the unnamed vehicle
// (pmu/dds_settings/vehicle.hpp).
std::string vehicle_of(const std::vector<std::string>& partitions) {
  return partitions.empty() ? std::string() : partitions.front();
}

std::string vehicles_list(const std::set<std::string>& vehicles) {
  std::string list;
  for (const auto& v : vehicles) list += (list.empty() ? "" : ", ") + (v.empty() ? std::string("(unnamed)") : v);
  return list;
}

}  // namespace

std::set<std::string> vehicles_on_domain(const pmu::dds::DdsContext& dds) {
  std::set<std::string> vehicles;
  for (const auto& w : dds.remote_writers().writers_of(topics::kHealth))
    if (pmu::dds::contract_of_type_name(w.type_name) == pmu::dds::contract_major())
      vehicles.insert(vehicle_of(w.partitions));
  return vehicles;
}

std::map<int, std::set<std::string>> other_contracts_on_domain(const pmu::dds::DdsContext& dds) {
  std::map<int, std::set<std::string>> others;
  for (const auto& w : dds.remote_writers().writers_of(topics::kHealth))
    if (const auto c = pmu::dds::contract_of_type_name(w.type_name); c && *c != pmu::dds::contract_major())
      others[*c].insert(vehicle_of(w.partitions));
  return others;
}

std::string other_contracts_text(const std::map<int, std::set<std::string>>& others) {
  std::string text;
  for (const auto& [contract, vehicles] : others)
    text += (text.empty() ? "" : ", ") + ("pmu-service of " + pmu::dds::contract_text(contract)) +
            " (vehicles: " + vehicles_list(vehicles) + ")";
  if (text.empty()) return text;
  return text + "; this pmuctl reads " + pmu::dds::contract_text(pmu::dds::contract_major()) +
         " only (docs/interface.md section 10 says what to do at the upgrade)";
}

std::string vehicles_seen_text(const std::set<std::string>& vehicles) {
  if (vehicles.empty()) return {};
  return "; vehicles seen: " + vehicles_list(vehicles) + " (choose one with --vehicle)";
}

std::string vehicle_text(const std::string& vehicle) {
  return vehicle.empty() ? "the unnamed vehicle" : "vehicle " + vehicle;
}

int no_service(const GlobalOptions& o, const pmu::dds::DdsContext& dds) {
  const auto vehicles = vehicles_on_domain(dds);
  const std::string domain = " on domain " + std::to_string(o.domain);
  // The vehicle asked for (or any, without --vehicle) served only in another contract: that
  // is why nothing matched, whatever this contract's services serve other vehicles.
  auto others = other_contracts_on_domain(dds);
  if (o.vehicle)
    for (auto it = others.begin(); it != others.end();)
      it = it->second.count(*o.vehicle) ? std::next(it) : others.erase(it);
  if (const std::string found = other_contracts_text(others); !found.empty())
    return fail(o, ExitStatus::NoAnswer,
                "no pmu-service of " + pmu::dds::contract_text(pmu::dds::contract_major()) +
                    (o.vehicle ? " for " + vehicle_text(*o.vehicle) : std::string()) + domain + "; found " + found);
  if (!o.vehicle || vehicles.empty())
    return fail(o, ExitStatus::NoAnswer,
                "no pmu-service" + (o.vehicle ? " of " + vehicle_text(*o.vehicle) : std::string()) + domain);
  return fail(o, ExitStatus::BadUsage,
              "no pmu-service of " + vehicle_text(*o.vehicle) + domain + vehicles_seen_text(vehicles));
}

int nothing_heard(const GlobalOptions& o) {
  return fail(o, ExitStatus::NoAnswer,
              "no pmu-service" + (o.vehicle ? " of " + vehicle_text(*o.vehicle) : std::string()) + " on domain " +
                  std::to_string(o.domain));
}

std::size_t writers_expected(const pmu::dds::DdsContext& dds, eprosima::fastdds::dds::DataReader& reader,
                             const std::string& topic) {
  eprosima::fastdds::dds::SubscriptionMatchedStatus st;
  reader.get_subscription_matched_status(st);
  return static_cast<std::size_t>(std::max(st.current_count, 0)) +
         dds.remote_writers().participants_without_writer(pmu::dds::kServiceParticipantName, topic);
}

}  // namespace pmu::tools
