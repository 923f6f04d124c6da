#include "pmuctl/verbs/service_presence.hpp"

#include "pmu/idl/topics.hpp"
#include "pmuctl/verbs/exit_status.hpp"

namespace pmu::tools {

std::set<std::string> vehicles_on_domain(const pmu::dds::DdsContext& dds) {
  std::set<std::string> vehicles;
  // A service's writers sit in its vehicle's partition, or in none for the unnamed vehicle
  // (service/vehicle.hpp).
  for (const auto& partitions : dds.remote_writers().partitions_writing(topics::kHealth))
    vehicles.insert(partitions.empty() ? std::string() : partitions.front());
  return vehicles;
}

std::string vehicles_seen_text(const std::set<std::string>& vehicles) {
  if (vehicles.empty()) return {};
  std::string list;
  for (const auto& v : vehicles) list += (list.empty() ? "" : ", ") + (v.empty() ? std::string("(unnamed)") : v);
  return "; vehicles seen: " + list + " (choose one with --vehicle)";
}

std::string vehicle_text(const std::string& vehicle) {
  return vehicle.empty() ? "the unnamed vehicle" : "vehicle " + vehicle;
}

int no_service(const GlobalOptions& o, const pmu::dds::DdsContext& dds) {
  const auto vehicles = vehicles_on_domain(dds);
  const std::string domain = " on domain " + std::to_string(o.domain);
  if (!o.vehicle || vehicles.empty())
    return fail(o, ExitStatus::NoAnswer,
                "no pmu-service" + (o.vehicle ? " of " + vehicle_text(*o.vehicle) : std::string()) + domain);
  return fail(o, ExitStatus::BadUsage,
              "no pmu-service of " + vehicle_text(*o.vehicle) + domain + vehicles_seen_text(vehicles));
}

}  // namespace pmu::tools
