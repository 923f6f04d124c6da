#include "pmu/dds_settings/vehicle.hpp"

#include "pmu/dds_settings/quoted.hpp"

namespace pmu::dds {

std::string vehicle_name_problem(std::string_view name) {
  // Bytes: the IDL bound counts them (every character a vehicle name may hold is one byte).
  if (name.size() > kMaxVehicleNameLength)
    return "is " + std::to_string(name.size()) + " bytes; a vehicle name has at most " +
           std::to_string(kMaxVehicleNameLength) + " (it is a DDS key, string<15>)";
  for (std::size_t i = 0; i < name.size(); ++i) {
    const char ch = name[i];
    const bool ok = (ch >= 'a' && ch <= 'z') || (ch >= 'A' && ch <= 'Z') || (ch >= '0' && ch <= '9') || ch == '_' ||
                    ch == '-' || ch == '.';
    if (!ok)
      return "contains " + character_at(name, i) +
             "; a vehicle name is letters, digits, '_', '-' and '.' (it is also a DDS partition name, where "
             "other characters are patterns)";
  }
  return {};
}

std::vector<std::string> vehicle_partitions(const std::string& vehicle) {
  if (vehicle.empty()) return {};
  return {vehicle};
}

std::vector<std::string> every_vehicle_partitions() {
  // Every name a vehicle can have starts with one of these characters; "*" would also match
  // partitions that are not vehicles, such as the one a closing DdsContext parks its writers
  // in (dds_context.cpp), and keep its readers matched to writers being deleted.
  return {"", "[A-Za-z0-9_.-]*"};
}

bool partitions_address_only(const std::vector<std::string>& writer_partitions, const std::string& vehicle) {
  if (vehicle.empty()) {
    for (const auto& p : writer_partitions)
      if (!p.empty()) return false;
    return true;
  }
  return writer_partitions.size() == 1 && writer_partitions.front() == vehicle;
}

}  // namespace pmu::dds
