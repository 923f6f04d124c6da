#include "pmuctl/verbs/energy_verb.hpp"

#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fastdds/dds/core/status/SubscriptionMatchedStatus.hpp>
#include <fastdds/dds/subscriber/SampleInfo.hpp>
#include <map>
#include <nlohmann/json.hpp>
#include <set>
#include <thread>
#include <tuple>

#include "pmu/dds/contract_names.hpp"
#include "pmu/idl/energyPubSubTypes.h"
#include "pmu/idl/guarded_type.hpp"
#include "pmu/idl/topics.hpp"
#include "pmuctl/verbs/exit_status.hpp"
#include "pmuctl/verbs/service_presence.hpp"
#include "pmuctl/verbs/state_settle.hpp"
#include "pmuctl/view/sample_fields.hpp"

namespace pmu::tools {
// A namespace of its own: the unity builds put this file in one translation unit with the
// other verbs, whose helpers have the same names.
namespace energy_verb {
namespace {

using namespace eprosima::fastdds::dds;
using Clock = std::chrono::steady_clock;
using Json = nlohmann::json;
using Key = std::tuple<std::string, std::string, std::uint16_t>;  // vehicle, bus, address

bool selected(const GlobalOptions& o, const pmu::v4::Energy& e) {
  return (!o.vehicle || *o.vehicle == e.vehicle().to_string()) && (o.bus.empty() || o.bus == e.bus().to_string()) &&
         (!o.address || *o.address == e.address());
}

// NaN (not known) is null in JSON. A float as the shortest decimal that is the same float32,
// as the other verbs print the contract's floats.
Json number_or_null(float v) {
  return std::isfinite(v) ? Json(std::strtod(shortest(v).c_str(), nullptr)) : Json(nullptr);
}
Json number_or_null(double v) { return std::isfinite(v) ? Json(v) : Json(nullptr); }

Json battery_json(const pmu::v4::EnergyBattery& b) {
  return {{"power", number_or_null(b.power())},
          {"used_wh", number_or_null(b.used_wh())},
          {"integrated_s", number_or_null(b.integrated_s())},
          {"endurance_s", number_or_null(b.endurance_s())},
          {"critical_voltage", number_or_null(b.critical_voltage())}};
}

// "12.3 W", or "-" when not known.
std::string watts(float w) {
  if (!std::isfinite(w)) return "-";
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.1f W", static_cast<double>(w));
  return buf;
}

// "1 h 02 min", "14 min", "45 s"; "-" when not known.
std::string duration_text(float s) {
  if (!std::isfinite(s)) return "-";
  const long total = std::lround(static_cast<double>(s));
  char buf[32];
  if (total >= 3600)
    std::snprintf(buf, sizeof buf, "%ld h %02ld min", total / 3600, (total % 3600) / 60);
  else if (total >= 60)
    std::snprintf(buf, sizeof buf, "%ld min", total / 60);
  else
    std::snprintf(buf, sizeof buf, "%ld s", total);
  return buf;
}

void print_battery(const char* name, const pmu::v4::EnergyBattery& b) {
  std::printf("  %-10s %10s  used %8.3f Wh in %.0f s  endurance %s to %.1f V\n", name, watts(b.power()).c_str(),
              b.used_wh(), static_cast<double>(b.integrated_s()), duration_text(b.endurance_s()).c_str(),
              static_cast<double>(b.critical_voltage()));
}

void print(const GlobalOptions& o, const pmu::v4::Energy& e) {
  if (o.json) {
    Json values{{"avionics_power", number_or_null(e.avionics_power())},
                {"output_28v_power", number_or_null(e.output_28v_power())},
                {"payload_power", number_or_null(e.payload_power())},
                {"servo_power", number_or_null(e.servo_power())},
                {"generator_power", number_or_null(e.generator_power())},
                {"battery_a", battery_json(e.battery_a())},
                {"battery_b", battery_json(e.battery_b())}};
    Json j{{"topic", "energy"},
           {"vehicle", e.vehicle().to_string()},
           {"bus", e.bus().to_string()},
           {"address", e.address()},
           {"values", values},
           {"contract", pmu::dds::contract_major()}};
    std::printf("%s\n", j.dump(-1, ' ', false, Json::error_handler_t::replace).c_str());
    return;
  }
  std::printf("%s\n", device_label(e.vehicle().to_string(), e.bus().to_string(), e.address()).c_str());
  std::printf("  %-10s %10s  %-10s %10s  %-10s %10s  %-10s %10s\n", "avionics", watts(e.avionics_power()).c_str(),
              "28 V", watts(e.output_28v_power()).c_str(), "payload", watts(e.payload_power()).c_str(), "servo",
              watts(e.servo_power()).c_str());
  std::printf("  %-10s %10s\n", "generator", watts(e.generator_power()).c_str());
  print_battery("battery A", e.battery_a());
  print_battery("battery B", e.battery_b());
}

int run(const GlobalOptions& o) {
  pmu::dds::DdsContext dds(o.domain, o.qos_file, "pmuctl", o.security, pmu::dds::Transport::Default, o.network,
                           partitions_for(o));
  DataReader& reader =
      dds.reader(dds.topic(topics::kEnergy, TypeSupport(new idl::Guarded<pmu::v4::EnergyPubSubType>())),
                 qos_profiles::kState);
  const auto deadline = Clock::now() + std::chrono::duration<double>(o.timeout.value_or(3.0));
  StateSettle settle(std::chrono::milliseconds(300));
  std::map<Key, pmu::v4::Energy> latest;
  std::map<InstanceHandle_t, Key> handles;
  std::set<InstanceHandle_t> writers;
  while (Clock::now() < deadline) {
    pmu::v4::Energy e;
    SampleInfo info;
    while (reader.take_next_sample(&e, &info) == ReturnCode_t::RETCODE_OK) {
      writers.insert(info.publication_handle);
      if (!info.valid_data) {
        // Disposed (a PMU that moved to another address): its figures are gone with it.
        if (auto it = handles.find(info.instance_handle); it != handles.end() && info.instance_state != ALIVE_INSTANCE_STATE) {
          latest.erase(it->second);
          handles.erase(it);
        }
        continue;
      }
      if (!selected(o, e)) continue;
      const Key key{e.vehicle().to_string(), e.bus().to_string(), e.address()};
      latest[key] = e;
      handles[info.instance_handle] = key;
    }
    settle.observe(Clock::now(), writers_expected(dds, reader, topics::kEnergy), writers.size());
    if (settle.settled(Clock::now())) break;
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  if (latest.empty()) {
    SubscriptionMatchedStatus st;
    reader.get_subscription_matched_status(st);
    if (st.current_count == 0) return no_service(o, dds);
    return fail(o, ExitStatus::BadUsage,
                std::string("no energy figures from ") +
                    (o.address ? "PMU " + std::to_string(*o.address) : std::string("any PMU")) +
                    (o.bus.empty() ? std::string() : " on bus " + o.bus));
  }
  for (const auto& [key, e] : latest) print(o, e);
  return 0;
}

}  // namespace
}  // namespace energy_verb

int run_energy(const GlobalOptions& o) { return energy_verb::run(o); }

}  // namespace pmu::tools
