#include "pmuctl/verbs/state_verbs.hpp"

#include <unistd.h>

#include <CLI/CLI.hpp>
#include <chrono>
#include <ctime>
#include <cstdio>
#include <fastdds/dds/core/status/SubscriptionMatchedStatus.hpp>
#include <fastdds/dds/subscriber/SampleInfo.hpp>
#include <map>
#include <memory>
#include <set>
#include <thread>
#include <tuple>
#include <variant>
#include <vector>

#include "pmu/codec/parameters.hpp"
#include "pmu/command/command.hpp"
#include "pmu/dds_settings/vehicle.hpp"
#include "pmu/dds/dds_context.hpp"
#include "pmu/idl/alarmsPubSubTypes.h"
#include "pmu/idl/canopenPubSubTypes.h"
#include "pmu/idl/commandPubSubTypes.h"
#include "pmu/idl/guarded_type.hpp"
#include "pmu/idl/statePubSubTypes.h"
#include "pmu/idl/telemetryPubSubTypes.h"
#include "pmu/idl/topics.hpp"
#include "pmu/transport/stop_signals.hpp"
#include "pmuctl/verbs/alarm_sample.hpp"
#include "pmuctl/verbs/role_verbs.hpp"
#include "pmuctl/call/command_channel.hpp"
#include "pmuctl/call/exit_status.hpp"
#include "pmuctl/call/option_values.hpp"
#include "pmuctl/call/service_presence.hpp"
#include "pmuctl/call/state_settle.hpp"
#include "pmuctl/view/alarm_marker.hpp"
#include "pmuctl/view/sample_fields.hpp"
#include "pmuctl/view/sample_json.hpp"
#include "pmuctl/view/table_text.hpp"
#include "pmuctl/call/context_lease.hpp"

namespace pmu::tools {
namespace {

using namespace eprosima::fastdds::dds;
using Clock = std::chrono::steady_clock;


// The names `config get` takes: pmu::v5::Config's fields.
std::string config_names() {
  std::string names;
  for (const auto& spec : codec::parameter_table()) names += std::string(spec.name) + ", ";
  return names + "outputs, generation_enabled";
}

double seconds_of(const eprosima::fastrtps::rtps::Time_t& t) { return t.seconds() + t.nanosec() / 1e9; }


// `no_address`: the words for "every device" ("any device", "no device").
std::string device_name(const GlobalOptions& o, const char* no_address = "any device") {
  std::string d = o.address ? "device " + std::to_string(*o.address) : std::string(no_address);
  d += o.bus.empty() ? std::string() : " on " + o.bus;
  if (o.vehicle) d += o.vehicle->empty() ? " of the unnamed vehicle" : " of vehicle " + *o.vehicle;
  return d;
}

// "PMU 9 not seen on bus can0 of vehicle uav1", "no device seen on bus nope".
std::string not_seen(const GlobalOptions& o) {
  std::string d = o.address ? "PMU " + std::to_string(*o.address) + " not seen" : std::string("no device seen");
  d += o.bus.empty() ? std::string() : " on bus " + o.bus;
  if (o.vehicle) d += o.vehicle->empty() ? " of the unnamed vehicle" : " of vehicle " + *o.vehicle;
  return d;
}

// A device on DDS: the samples' keys. `address` is a PMU's CAN address, a battery's node or
// an MPPT's device id, told apart by `kind`.
struct DeviceId {
  std::string vehicle;
  std::string bus;
  std::uint16_t address;
  pmu::v5::DeviceKind kind = pmu::v5::KIND_PMU;
  bool operator<(const DeviceId& o) const {
    return std::tie(vehicle, bus, kind, address) < std::tie(o.vehicle, o.bus, o.kind, o.address);
  }
};

template <class T>
DeviceId id_of(const T& s) {
  return {s.vehicle().to_string(), s.bus().to_string(), s.address()};
}
DeviceId id_of(const pmu::v5::Health& s) {
  return {s.vehicle().to_string(), s.bus().to_string(), s.address(), s.kind()};
}
DeviceId id_of(const pmu::v5::Battery& s) {
  return {s.vehicle().to_string(), s.bus().to_string(), s.node(), pmu::v5::KIND_BATTERY};
}
DeviceId id_of(const pmu::v5::BatteryCells& s) {
  return {s.vehicle().to_string(), s.bus().to_string(), s.node(), pmu::v5::KIND_BATTERY};
}
DeviceId id_of(const pmu::v5::Mppt& s) {
  return {s.vehicle().to_string(), s.bus().to_string(), s.device(), pmu::v5::KIND_MPPT};
}

// --address names a PMU: batteries and MPPTs are selected by vehicle and bus alone, and
// drop out when a PMU is named.
bool selected(const GlobalOptions& o, const DeviceId& d) {
  return (!o.vehicle || *o.vehicle == d.vehicle) && (o.bus.empty() || o.bus == d.bus) &&
         (!o.address || (d.kind == pmu::v5::KIND_PMU && *o.address == d.address));
}

// "can0/1" for a PMU, "can0/battery2" and "can0/mppt4" for the others.
std::string label(const DeviceId& d) {
  if (d.kind == pmu::v5::KIND_PMU) return device_label(d.vehicle, d.bus, d.address);
  return (d.vehicle.empty() ? std::string() : d.vehicle + "/") + d.bus + "/" + to_string(d.kind) +
         std::to_string(d.address);
}

// The JSON key of a device's number: the contract's key name of its type.
const char* number_key(pmu::v5::DeviceKind k) {
  return k == pmu::v5::KIND_BATTERY ? "node" : k == pmu::v5::KIND_MPPT ? "device" : "address";
}

// Reads every sample of one state topic (TRANSIENT_LOCAL: the service's current values
// arrive at once) and keeps the latest per device.
template <class T, class PubSub>
class StateCollector {
 public:
  StateCollector(pmu::dds::DdsContext& dds, const char* topic)
      : topic_(topic),
        reader_(dds.reader(dds.topic(topic, TypeSupport(new idl::Guarded<PubSub>())), qos_profiles::kState)) {}

  void poll(const GlobalOptions& o) {
    T sample;
    SampleInfo info;
    while (reader_.take_next_sample(&sample, &info) == ReturnCode_t::RETCODE_OK) {
      writers_heard_.insert(info.publication_handle);
      if (!info.valid_data) {
        // Disposed (a PMU that moved to another address): that device is not there any more.
        if (info.instance_state != ALIVE_INSTANCE_STATE) forget(info.instance_handle);
        continue;
      }
      if (!selected(o, id_of(sample))) continue;
      latest_[id_of(sample)] = sample;
      handles_[info.instance_handle] = id_of(sample);
    }
  }
  bool matched() { return matched_writers() > 0; }
  std::size_t matched_writers() {
    SubscriptionMatchedStatus st;
    reader_.get_subscription_matched_status(st);
    return st.current_count > 0 ? static_cast<std::size_t>(st.current_count) : 0;
  }
  // Writers (services) whose samples have arrived, valid or not.
  std::size_t writers_heard() const { return writers_heard_.size(); }
  const std::string& topic() const { return topic_; }
  const std::map<DeviceId, T>& latest() const { return latest_; }

 private:
  void forget(const InstanceHandle_t& h) {
    auto it = handles_.find(h);
    if (it == handles_.end()) return;
    latest_.erase(it->second);
    handles_.erase(it);
  }
  std::string topic_;
  DataReader& reader_;
  std::map<DeviceId, T> latest_;
  std::map<InstanceHandle_t, DeviceId> handles_;
  std::set<InstanceHandle_t> writers_heard_;
};

}  // namespace

Clock::time_point wait_end(const GlobalOptions& o, double default_timeout) {
  if (o.deadline) return *o.deadline;
  return Clock::now() + std::chrono::duration_cast<Clock::duration>(
                            std::chrono::duration<double>(o.timeout.value_or(default_timeout)));
}

namespace {

// Waits for the state of the selected devices: returns once every service discovered has sent
// its state and nothing new came for a short quiet time (state_settle.hpp), or at the timeout.
template <class Collector>
int collect(const GlobalOptions& o, const pmu::dds::DdsContext& dds, Collector& c, double default_timeout) {
  const auto deadline = wait_end(o, default_timeout);
  StateSettle settle(std::chrono::milliseconds(300));
  while (Clock::now() < deadline) {
    c.poll(o);
    // Services whose writer is still being discovered will match (or prove to be another
    // vehicle's) in a moment: they are waited for as matched ones are.
    const auto coming = dds.remote_writers().participants_without_writer(pmu::dds::kServiceParticipantName, c.topic());
    settle.observe(Clock::now(), c.matched_writers() + coming, c.writers_heard());
    if (settle.settled(Clock::now())) break;
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  if (!c.latest().empty()) return 0;
  if (!c.matched()) return no_service(o, dds);
  if (c.writers_heard() == 0) return nothing_heard(o);
  return fail(o, ExitStatus::BadUsage, not_seen(o));
}

// `with_kind`: the lines of verbs that show every kind of device (list, health) say which.
void print_json(const char* topic, const DeviceId& d, const Json& values, std::optional<double> time = std::nullopt,
                bool with_kind = false) {
  Json j;
  j["topic"] = topic;
  j["vehicle"] = d.vehicle;
  j["bus"] = d.bus;
  if (with_kind) j["kind"] = to_string(d.kind);
  j[number_key(d.kind)] = d.address;
  if (time) j["time"] = *time;
  j["values"] = values;
  // Last, so scripts that match the keys before it in their order (as the VM suites do) are
  // not disturbed by it: the contract the values were read as.
  j["contract"] = pmu::dds::contract_major();
  std::printf("%s\n", j.dump().c_str());
}

// "23:05:08.507": the sample's source time (the CAN frame's receive time), local time.
std::string clock_text(double t) {
  const auto secs = static_cast<std::time_t>(t);
  std::tm tm{};
  localtime_r(&secs, &tm);
  char buf[32];
  const std::size_t n = std::strftime(buf, sizeof buf, "%H:%M:%S", &tm);
  std::snprintf(buf + n, sizeof buf - n, ".%03d", static_cast<int>((t - static_cast<double>(secs)) * 1000));
  return buf;
}

template <class Collector>
int print_state(const GlobalOptions& o, const pmu::dds::DdsContext& dds, Collector& c, const char* topic,
                bool with_kind = false) {
  if (int rc = collect(o, dds, c, 3.0)) return rc;
  for (const auto& [key, s] : c.latest()) {
    if (o.json)
      print_json(topic, key, values_of(s), std::nullopt, with_kind);
    else
      std::printf("%s", value_block(label(key), fields_of(s)).c_str());
  }
  return 0;
}

// ---- watch --------------------------------------------------------------------------------

struct TelemetryLine {
  std::string topic;
  DeviceId device;
  double time;  // the sample's source timestamp, s since the Unix epoch
  SampleFields values;
};

class TelemetryReader {
 public:
  virtual ~TelemetryReader() = default;
  virtual bool take(const GlobalOptions& o, TelemetryLine& out) = 0;
  virtual bool matched() const = 0;
  virtual const std::string& name() const = 0;  // the topic's last word(s): "voltages", "low_rate/voltages"
};

template <class T, class PubSub>
class TypedTelemetryReader final : public TelemetryReader {
 public:
  TypedTelemetryReader(pmu::dds::DdsContext& dds, const char* topic)
      : name_(std::string(topic).substr(4)),
        reader_(dds.reader(dds.topic(topic, TypeSupport(new idl::Guarded<PubSub>())), qos_profiles::kTelemetry)) {}
  bool take(const GlobalOptions& o, TelemetryLine& out) override {
    T sample;
    SampleInfo info;
    while (reader_.take_next_sample(&sample, &info) == ReturnCode_t::RETCODE_OK) {
      if (!info.valid_data || !selected(o, id_of(sample))) continue;
      out = {name_, id_of(sample), seconds_of(info.source_timestamp), fields_of(sample)};
      return true;
    }
    return false;
  }
  bool matched() const override {
    SubscriptionMatchedStatus st;
    reader_.get_subscription_matched_status(st);
    return st.current_count > 0;
  }
  const std::string& name() const override { return name_; }

 private:
  std::string name_;
  DataReader& reader_;
};

}  // namespace

pmu::dds::Partitions partitions_for(const GlobalOptions& o) {
  return {dds::vehicle_partitions(o.vehicle.value_or(std::string())),
          o.vehicle ? dds::vehicle_partitions(*o.vehicle) : dds::every_vehicle_partitions()};
}

std::string device_label(const std::string& vehicle, const std::string& bus, std::uint16_t address) {
  return (vehicle.empty() ? std::string() : vehicle + "/") + bus + "/" + std::to_string(address);
}

int run_watch(const GlobalOptions& o, long count) {
  // Ctrl-C or SIGTERM ends the watch like its count or timeout does (the summary and the exit
  // status follow), read before Fast DDS starts its threads.
  pmu::transport::StopSignals stop;
  ContextLease lease(o, kPmuctlParticipant);
  pmu::dds::DdsContext& dds = *lease;
  std::vector<std::unique_ptr<TelemetryReader>> readers;
  // --low-rate: only the low-rate topics' writers match, so only their samples cross the link.
  const bool low = o.low_rate;
  readers.push_back(std::make_unique<TypedTelemetryReader<pmu::v5::Voltages, pmu::v5::VoltagesPubSubType>>(
      dds, low ? topics::kLowRateVoltages : topics::kVoltages));
  readers.push_back(std::make_unique<TypedTelemetryReader<pmu::v5::Currents, pmu::v5::CurrentsPubSubType>>(
      dds, low ? topics::kLowRateCurrents : topics::kCurrents));
  readers.push_back(std::make_unique<TypedTelemetryReader<pmu::v5::BatteryEnergy, pmu::v5::BatteryEnergyPubSubType>>(
      dds, low ? topics::kLowRateBatteryEnergy : topics::kBatteryEnergy));
  readers.push_back(std::make_unique<TypedTelemetryReader<pmu::v5::Temperatures, pmu::v5::TemperaturesPubSubType>>(
      dds, low ? topics::kLowRateTemperatures : topics::kTemperatures));
  readers.push_back(std::make_unique<TypedTelemetryReader<pmu::v5::Status, pmu::v5::StatusPubSubType>>(
      dds, low ? topics::kLowRateStatus : topics::kStatus));
  // Batteries and MPPTs have no low-rate topics: their canopen_publish_period already holds
  // them to a few samples a second.
  // DDS-Security permissions made before these topics existed do not grant them: then watch
  // shows the PMUs and says what it leaves out, rather than nothing at all.
  if (!low) {
    try {
      readers.push_back(
          std::make_unique<TypedTelemetryReader<pmu::v5::Battery, pmu::v5::BatteryPubSubType>>(dds, topics::kBattery));
      readers.push_back(std::make_unique<TypedTelemetryReader<pmu::v5::BatteryCells, pmu::v5::BatteryCellsPubSubType>>(
          dds, topics::kBatteryCells));
      readers.push_back(
          std::make_unique<TypedTelemetryReader<pmu::v5::Mppt, pmu::v5::MpptPubSubType>>(dds, topics::kMppt));
    } catch (const pmu::dds::DdsError& e) {
      std::fprintf(stderr, "pmuctl: not showing batteries and MPPTs: %s\n", e.what());
    }
  }

  // Each device's alarms beside its values (interface.md 1.6). Permissions made before
  // pmu/alarms existed do not grant it: then watch shows the telemetry and says what it leaves out.
  DataReader* alarm_reader = nullptr;
  try {
    alarm_reader = &dds.reader(dds.topic(topics::kAlarms, TypeSupport(new idl::Guarded<pmu::v5::AlarmPubSubType>())),
                               qos_profiles::kAlarms);
  } catch (const pmu::dds::DdsError& e) {
    std::fprintf(stderr, "pmuctl: not showing alarms: %s\n", e.what());
  }
  // The latest sample of each alarm instance, NORMAL ones too: one that went back to NORMAL
  // takes its marker away.
  std::map<std::tuple<std::string, std::string, std::string, std::uint16_t, std::string>, AlarmEntry> alarms;
  const auto alarm_list = [&alarms] {
    std::vector<AlarmEntry> list;
    for (const auto& [key, a] : alarms) list.push_back(a);
    return list;
  };

  // The instances of hot-standby pairs (interface.md 1.10): a line when an instance's role or
  // term changes (a takeover, a silent owner), and a `pair:` section atop the table.
  RoleCollector roles(o, dds);
  std::map<std::pair<std::string, std::string>, std::string> roles_printed;

  // Every row says its device's health and its values' age: a device gone OFFLINE keeps
  // its last row, which must not look live (docs/safety.md H7). --low-rate reads the state
  // from pmu/low_rate/health, which the service writes when it changes: pmu/health's sample a
  // second (its frame age and counters, which watch does not show) would cross the link too.
  using HealthCollector = StateCollector<pmu::v5::Health, pmu::v5::HealthPubSubType>;
  std::unique_ptr<HealthCollector> health_reader;
  if (low) {
    // Permissions made before pmu/low_rate/health existed do not grant it.
    try {
      health_reader = std::make_unique<HealthCollector>(dds, topics::kLowRateHealth);
    } catch (const pmu::dds::DdsError& e) {
      std::fprintf(stderr, "pmuctl: reading pmu/health, not pmu/low_rate/health: %s\n", e.what());
    }
  }
  if (!health_reader) health_reader = std::make_unique<HealthCollector>(dds, topics::kHealth);
  HealthCollector& health = *health_reader;
  const auto health_of = [&health](const DeviceId& d) -> std::optional<pmu::v5::HealthState> {
    const auto it = health.latest().find(d);
    if (it == health.latest().end()) return std::nullopt;
    return it->second.state();
  };
  const auto now_s = [] {
    return std::chrono::duration<double>(std::chrono::system_clock::now().time_since_epoch()).count();
  };
  const bool refresh = !o.json && isatty(STDOUT_FILENO);
  const auto deadline = o.timeout ? Clock::now() + std::chrono::duration<double>(*o.timeout) : Clock::time_point::max();
  std::map<std::pair<DeviceId, std::string>, TelemetryLine> latest;
  long seen = 0;
  auto next_draw = Clock::now();
  while (stop.received() == 0 && Clock::now() < deadline && (count <= 0 || seen < count)) {
    bool any = false;
    health.poll(o);
    // Before the telemetry, so the lines of a device whose alarm came with them carry its marker.
    pmu::v5::Alarm alarm;
    SampleInfo alarm_info;
    while (alarm_reader && alarm_reader->take_next_sample(&alarm, &alarm_info) == ReturnCode_t::RETCODE_OK) {
      if (!alarm_info.valid_data) continue;
      const AlarmEntry a = alarm_entry_of(alarm);
      if (!selected(o, a)) continue;
      alarms[{a.vehicle, a.bus, a.kind, a.device, a.code}] = a;
      any = true;
      // Not counted by --count, which counts telemetry samples.
      if (o.json) {
        std::printf(
            "%s\n",
            alarm_json(a, pmu::dds::contract_major()).dump(-1, ' ', false, Json::error_handler_t::replace).c_str());
      } else if (!refresh) {
        std::printf("%s %s alarms %s %s %s %s\n", clock_text(static_cast<double>(a.since) / 1e9).c_str(),
                    alarm_source(a).c_str(), a.critical ? "CRITICAL" : "WARNING", to_string(a.state), a.code.c_str(),
                    a.message.c_str());
      }
    }
    const auto instances = roles.seen();
    for (const auto& c : shown_role_changes(instances, roles_printed)) {
      any = true;
      // Not counted by --count either.
      if (o.json)
        std::printf(
            "%s\n",
            role_json(c.now, pmu::dds::contract_major()).dump(-1, ' ', false, Json::error_handler_t::replace).c_str());
      else if (!refresh)
        std::printf("%s %s\n", clock_text(now_s()).c_str(), role_change_text(c).c_str());
    }
    TelemetryLine line;
    for (auto& r : readers) {
      while ((count <= 0 || seen < count) && r->take(o, line)) {
        any = true;
        ++seen;
        if (o.json) {
          print_json(line.topic.c_str(), line.device, json_of(line.values), line.time);
        } else if (!refresh) {
          const std::string marker = alarm_marker(alarms_of(alarm_list(), label(line.device)));
          std::printf("%s %s %s %s%s %s\n", clock_text(line.time).c_str(), label(line.device).c_str(),
                      line.topic.c_str(), freshness(health_of(line.device), now_s() - line.time).c_str(),
                      marker.empty() ? "" : (" " + marker).c_str(), row_values(line.values).c_str());
        }
        latest[{line.device, line.topic}] = line;
      }
    }
    if (any) std::fflush(stdout);
    if (refresh && Clock::now() >= next_draw) {
      next_draw = Clock::now() + std::chrono::milliseconds(500);
      std::printf("\033[H\033[2J");  // home + clear: a refreshing table
      std::printf("pmuctl watch — domain %d — %ld samples (Ctrl-C to stop)\n\n", o.domain, seen);
      std::vector<WatchRow> rows;
      const double now = now_s();
      // Topics in the contract's order (the readers'), devices in order within each.
      for (const auto& r : readers)
        for (const auto& [key, l] : latest)
          if (l.topic == r->name())
            rows.push_back({label(l.device), l.topic, health_of(l.device), now - l.time, l.values});
      if (!instances.empty()) {
        std::printf("pair:\n");
        for (const auto& l : aligned_columns(role_rows(instances))) std::printf("%s\n", l.c_str());
      }
      for (const auto& r : watch_table(rows, alarm_list())) std::printf("%s\n", r.c_str());
      std::fflush(stdout);
    }
    if (!any) std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
  if (seen == 0) {
    bool matched = false;
    for (auto& r : readers) matched = matched || r->matched();
    if (!matched) return no_service(o, dds);
    return fail(o, ExitStatus::NotDone,
                "no telemetry received from " + device_name(o) + " on domain " + std::to_string(o.domain));
  }
  if (count > 0 && seen < count)
    return fail(o, ExitStatus::NotDone,
                std::to_string(seen) + " of " + std::to_string(count) + " samples received before the timeout");
  return 0;
}

// "v5", or "v5, v4" for a vehicle whose service also serves contract 4's consumers.
std::string contracts_cell(const std::set<int>& contracts) {
  std::string cell;
  for (auto it = contracts.rbegin(); it != contracts.rend(); ++it)
    cell += (cell.empty() ? "v" : ", v") + std::to_string(*it);
  return cell;
}

// In a call `pmuctl agent` serves: each listed vehicle's one PMU, which that worker's later
// commands to the vehicle then take without reading its health again (target_memory.hpp); a
// vehicle listed with several is forgotten, so its commands find out which.
// Returns the vehicles remembered.
template <typename Latest>
std::vector<std::string> remember_only_pmus(const Latest& latest, TargetMemory& memory) {
  std::map<std::string, std::vector<Target>> pmus;
  for (const auto& entry : latest)
    if (entry.first.kind == pmu::v5::KIND_PMU)
      pmus[entry.first.vehicle].push_back({entry.first.bus, entry.first.address});
  const auto now = TargetMemory::Clock::now();
  std::vector<std::string> remembered;
  for (const auto& [vehicle, found] : pmus) {
    const TargetQuery query{vehicle, "", std::nullopt};
    if (found.size() == 1) {
      memory.remember(query, found.front(), now);
      remembered.push_back(vehicle);
    } else {
      memory.forget(query);
    }
  }
  return remembered;
}

// The instances of hot-standby pairs seen on pmu/role (interface.md 1.10): a table after the
// devices' (a blank line between), or a JSON line each. Nothing when no service is one of a pair.
static void print_pairs(const GlobalOptions& o, const std::vector<SeenInstance>& instances) {
  if (instances.empty()) return;
  if (o.json) {
    for (const auto& s : instances)
      std::printf("%s\n", role_json(s, pmu::dds::contract_major())
                              .dump(-1, ' ', false, nlohmann::json::error_handler_t::replace)
                              .c_str());
    return;
  }
  std::printf("\n");
  for (const auto& line : aligned_columns(role_rows(instances))) std::printf("%s\n", line.c_str());
}

// The list itself; `one_pmu`: the vehicles it found one PMU of, in a call the agent serves.
static int list_once(const GlobalOptions& o, std::vector<std::string>& one_pmu);

int run_list(const GlobalOptions& o) {
  std::vector<std::string> one_pmu;
  const int rc = list_once(o, one_pmu);
  // After its lease: the channels borrow the same participant.
  if (rc == 0) open_command_channels(o, one_pmu);
  return rc;
}

static int list_once(const GlobalOptions& o, std::vector<std::string>& one_pmu) {
  ContextLease lease(o, kPmuctlParticipant);
  pmu::dds::DdsContext& dds = *lease;
  StateCollector<pmu::v5::Health, pmu::v5::HealthPubSubType> health(dds, topics::kHealth);
  StateCollector<pmu::v5::DeviceInfo, pmu::v5::DeviceInfoPubSubType> info(dds, topics::kInfo);
  RoleCollector roles(o, dds);
  const auto deadline = wait_end(o, 3.0);
  const int collected = collect(o, dds, health, 3.0);
  roles.wait_for_peers(deadline);
  if (int rc = collected) {
    // A pair with no bus owner writes no state, but its instances say so on pmu/role.
    print_pairs(o, roles.seen());
    return rc;
  }
  info.poll(o);
  if (o.pool && o.bus.empty() && !o.address) one_pmu = remember_only_pmus(health.latest(), o.pool->targets());
  // Every contract each vehicle's services serve; those of other contracts only discovery sees.
  std::map<std::string, std::set<int>> contracts;
  for (const auto& v : vehicles_on_domain(dds)) contracts[v].insert(pmu::dds::contract_major());
  for (const auto& [contract, vehicles] : other_contracts_on_domain(dds))
    for (const auto& v : vehicles)
      if (!o.vehicle || *o.vehicle == v) contracts[v].insert(contract);
  std::vector<std::vector<std::string>> rows{
      {"VEHICLE", "BUS", "DEVICE", "SERIAL", "FIRMWARE", "STATE", "BUS STATE", "LAST FRAME", "CONTRACT"}};
  std::set<std::string> listed;
  for (const auto& [key, h] : health.latest()) {
    listed.insert(key.vehicle);
    const auto it = info.latest().find(key);
    std::string fw = "-", serial = "-";
    if (it != info.latest().end()) {
      fw = std::to_string(it->second.firmware_major()) + "." + std::to_string(it->second.firmware_minor());
      serial = std::to_string(it->second.serial_number());
    }
    auto& served = contracts[key.vehicle];
    served.insert(pmu::dds::contract_major());  // read, so served, whatever discovery has said yet
    if (o.json) {
      Json j = values_of(h);
      j["serial_number"] = it != info.latest().end() ? Json(it->second.serial_number()) : Json(nullptr);
      j["firmware"] = it != info.latest().end() ? Json(fw) : Json(nullptr);
      j["contracts"] = Json(std::vector<int>(served.rbegin(), served.rend()));
      print_json("list", key, j, std::nullopt, true);
    } else {
      const SampleField age = *find_field(fields_of(h), "last_frame_age");  // "never", or the age
      // A battery or MPPT shows its kind with its number ("battery2"): it has no serial or firmware.
      const std::string number = key.kind == pmu::v5::KIND_PMU ? std::to_string(key.address)
                                                               : to_string(key.kind) + std::to_string(key.address);
      rows.push_back({key.vehicle.empty() ? "-" : key.vehicle, key.bus, number, serial, fw, to_string(h.state()),
                      to_string(h.bus_state()),
                      age.json.is_null() ? age.text : age_text(age.json.get<double>()) + " ago",
                      contracts_cell(served)});
    }
  }
  // Services this pmuctl cannot read: a row each, so the fleet's view shows them, with the
  // contract that keeps them out of the table.
  std::map<int, std::set<std::string>> unreadable;
  for (const auto& [vehicle, served] : contracts) {
    if (listed.count(vehicle) || served.count(pmu::dds::contract_major())) continue;
    for (const int c : served) unreadable[c].insert(vehicle);
    if (o.json) {
      Json j;
      j["topic"] = "list";
      j["vehicle"] = vehicle;
      j["values"] = Json{{"contracts", std::vector<int>(served.rbegin(), served.rend())}};
      j["contract"] = pmu::dds::contract_major();
      j["error"] = "serves " + pmu::dds::contract_text(*served.rbegin()) + ", which this pmuctl cannot read";
      std::printf("%s\n", j.dump().c_str());
    } else {
      rows.push_back(
          {vehicle.empty() ? "-" : vehicle, "?", "?", "-", "-", "UNREADABLE", "-", "-", contracts_cell(served)});
    }
  }
  if (!o.json)
    for (const auto& line : aligned_columns(rows)) std::printf("%s\n", line.c_str());
  if (!unreadable.empty()) std::fprintf(stderr, "pmuctl: UNREADABLE: %s\n", other_contracts_text(unreadable).c_str());
  print_pairs(o, roles.seen());
  return 0;
}

int run_info(const GlobalOptions& o) {
  ContextLease lease(o, kPmuctlParticipant);
  pmu::dds::DdsContext& dds = *lease;
  StateCollector<pmu::v5::DeviceInfo, pmu::v5::DeviceInfoPubSubType> c(dds, topics::kInfo);
  return print_state(o, dds, c, "info");
}

int run_health(const GlobalOptions& o) {
  ContextLease lease(o, kPmuctlParticipant);
  pmu::dds::DdsContext& dds = *lease;
  StateCollector<pmu::v5::Health, pmu::v5::HealthPubSubType> c(dds, topics::kHealth);
  return print_state(o, dds, c, "health", true);
}

int run_config_get(const GlobalOptions& o, const std::string& parameter) {
  if (!parameter.empty() && !codec::parameter_from_name(parameter) && parameter != "outputs" &&
      parameter != "generation_enabled") {
    return fail(o, ExitStatus::BadUsage,
                "unknown parameter '" + service::printable(parameter) + "'" + " (parameters: " + config_names() + ")");
  }
  ContextLease lease(o, kPmuctlParticipant);
  pmu::dds::DdsContext& dds = *lease;
  StateCollector<pmu::v5::Config, pmu::v5::ConfigPubSubType> c(dds, topics::kConfig);
  if (parameter.empty()) return print_state(o, dds, c, "config");
  if (int rc = collect(o, dds, c, 3.0)) return rc;
  for (const auto& [key, s] : c.latest()) {
    const SampleFields fields = fields_of(s);
    const SampleField* f = find_field(fields, parameter);
    if (!f) continue;
    if (o.json)
      print_json("config", key, Json{{parameter, f->json}});
    else
      std::printf("%s %s = %s\n", label(key).c_str(), parameter.c_str(), text_with_unit(*f).c_str());
  }
  return 0;
}

namespace {

// watch, list, info, health.
class StateVerbs : public Verb {
 public:
  StateVerbs(CLI::App& app, GlobalOptions& g) {
    watch_ = app.add_subcommand(
        "watch", "Live telemetry with each device's alarm marker: a refreshing table, or one JSON object per sample");
    watch_->add_option("--count", count_text_, "Stop after N telemetry samples (alarm samples are not counted)")
        ->type_name("N");
    watch_->add_flag("--low-rate", g.low_rate,
                     "The low-rate topics pmu/low_rate/*: at most one sample per device and packet per the "
                     "service's low_rate_period (1 s by default, 2 s with its link profile radio), for slow links");
    list_ = app.add_subcommand("list", "PMUs the service knows, with health");
    info_ = app.add_subcommand("info", "Serial number, firmware and features");
    health_ = app.add_subcommand("health", "Link, bus and device health");
  }
  bool chosen() const override { return *watch_ || *list_ || *info_ || *health_; }
  std::optional<int> take_values(const GlobalOptions& g) override {
    if (count_text_.empty()) return std::nullopt;
    const auto n = parse_count("--count", count_text_);
    if (const auto* why = std::get_if<std::string>(&n)) return fail(g, ExitStatus::BadUsage, *why);
    count_ = std::get<long>(n);
    return std::nullopt;
  }
  bool ends_by_itself() const override { return !*watch_; }
  bool reads_state() const override { return !*watch_; }
  int run(GlobalOptions& g) override {
    if (*watch_) return run_watch(g, count_);
    if (*list_) return run_list(g);
    if (*info_) return run_info(g);
    return run_health(g);
  }

 private:
  CLI::App* watch_;
  CLI::App* list_;
  CLI::App* info_;
  CLI::App* health_;
  std::string count_text_;
  long count_ = 0;
};

class ConfigGet : public Verb {
 public:
  explicit ConfigGet(CLI::App& config) {
    get_ = config.add_subcommand("get", "Show the stored parameters (or one)");
    get_->add_option("param", parameter_, "A parameter name, e.g. avionics_voltage");
  }
  bool chosen() const override { return get_->parsed(); }
  bool reads_state() const override { return true; }
  int run(GlobalOptions& g) override { return run_config_get(g, parameter_); }

 private:
  CLI::App* get_;
  std::string parameter_;
};

}  // namespace

std::unique_ptr<Verb> add_state_verbs(CLI::App& app, GlobalOptions& g) { return std::make_unique<StateVerbs>(app, g); }

std::unique_ptr<Verb> add_config_get(CLI::App& config) { return std::make_unique<ConfigGet>(config); }

}  // namespace pmu::tools
