// "No value" on the contract's topics over real Fast DDS (docs/interface.md 1.1, 1.4): what
// the service's own types hold as a sentinel (65535 rpm, 3,932,100 s, -1 s) or as not
// received is NaN in the samples the service writes, never a number a plot would draw; and
// the previous contract's participant (also_serve_contract, 10.3) writes the same moments as
// that contract did. One row a field and case; each row's device has an address of its own.
#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <functional>
#include <iterator>
#include <limits>
#include <map>
#include <string>
#include <string_view>

#include "pmu/dds/dds_context.hpp"
#include "pmu/endpoints/dds_publisher.hpp"
#include "pmu/idl/canopenPubSubTypes.h"
#include "pmu/idl/statePubSubTypes.h"
#include "pmu/idl/telemetryPubSubTypes.h"
#include "pmu/idl/topics.hpp"
#include "pmu/idl_previous/canopenPubSubTypes.h"
#include "pmu/idl_previous/statePubSubTypes.h"
#include "pmu/idl_previous/telemetryPubSubTypes.h"
#include "support/domain.hpp"
#include "support/wait.hpp"

namespace pmu::service::test {
namespace {

using namespace eprosima::fastdds::dds;
using namespace std::chrono_literals;

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

enum class Topic { Status, Health, Battery, Mppt };

template <std::size_t N>
std::size_t slot(const CanOpenValue (&table)[N], std::string_view name) {
  for (std::size_t i = 0; i < N; ++i)
    if (table[i].name == name) return i;
  ADD_FAILURE() << name << ": no such value";
  return 0;
}

struct Row {
  const char* name;
  Topic topic;
  const char* field;
  double value;     // what the service's own type holds (kNaN: not received)
  double current;   // the field in this contract's sample (kNaN: NaN)
  double previous;  // the field in the previous contract's sample
};

// Sentinels of the service's types, as the codec and the session fill them.
constexpr double kNoRpm = 65535, kNotDischarging = 65535.0 * 60, kNever = -1;

const Row kRows[] = {
    {"rpm_no_reading", Topic::Status, "generator_rpm", kNoRpm, kNaN, 65535},
    {"rpm_reading", Topic::Status, "generator_rpm", 6000, 6000, 6000},
    {"rpm_stopped", Topic::Status, "generator_rpm", 0, 0, 0},
    {"frame_age_never", Topic::Health, "last_frame_age", kNever, kNaN, -1},
    {"frame_age_heard", Topic::Health, "last_frame_age", 0.25, 0.25, 0.25},
    {"time_to_go_not_discharging", Topic::Battery, "time_to_go", kNotDischarging, kNaN, 3932100},
    {"time_to_go_discharging", Topic::Battery, "time_to_go", 5700, 5700, 5700},
    {"time_to_go_not_received", Topic::Battery, "time_to_go", kNaN, kNaN, kNaN},
    {"bms_state_not_received", Topic::Battery, "bms_state", kNaN, kNaN, 0},
    {"bms_state_received", Topic::Battery, "bms_state", 0xFEDCBA98, 0xFEDCBA98, 0xFEDCBA98},
    {"mppt_state_not_received", Topic::Mppt, "mppt_state", kNaN, kNaN, 0},
    {"mppt_state_received", Topic::Mppt, "mppt_state", 3, 3, 3},
    {"safety_not_received", Topic::Mppt, "safety_enabled", kNaN, kNaN, 0},
    {"safety_off", Topic::Mppt, "safety_enabled", 0, 0, 0},
    {"pwm_on", Topic::Mppt, "pwm_enabled", 1, 1, 1},
    {"pwm_not_received", Topic::Mppt, "pwm_enabled", kNaN, kNaN, 0},
    {"channel_not_received", Topic::Mppt, "channel_3_active", kNaN, kNaN, 0},
    {"channel_active", Topic::Mppt, "channel_3_active", 1, 1, 1},
};

// The row's device: PMU, battery node or MPPT device number 1 + its index (a battery's node
// and an MPPT's device id are octets).
std::uint16_t address_of(std::size_t row) { return static_cast<std::uint16_t>(1 + row); }

void report(DdsPublisher& p, const Row& r, std::uint16_t address) {
  const auto now = std::chrono::system_clock::time_point(std::chrono::seconds(1700000000));
  switch (r.topic) {
    case Topic::Status: {
      codec::Status st;
      st.generator_rpm = static_cast<std::uint16_t>(r.value);
      codec::PmuMessage m;
      m.packet = codec::PacketId::Status;
      m.address = address;
      m.payload = st;
      p.on_telemetry(DeviceKey{"can0", address, DeviceKind::Pmu}, m, now);
      break;
    }
    case Topic::Health: {
      HealthReport h;
      h.state = HealthState::Online;
      h.last_frame_age = r.value;
      p.on_health(DeviceKey{"can0", address, DeviceKind::Pmu}, h);
      break;
    }
    case Topic::Battery: {
      BatteryState b;
      b.values[slot(kBatteryValues, "voltage")] = 48;  // a sample with something received
      b.values[slot(kBatteryValues, r.field)] = r.value;
      p.on_battery(DeviceKey{"can0", address, DeviceKind::Battery}, b, now);
      break;
    }
    case Topic::Mppt: {
      MpptState m;
      m.values[slot(kMpptValues, "temperature")] = 30;
      m.values[slot(kMpptValues, r.field)] = r.value;
      p.on_mppt(DeviceKey{"can0", address, DeviceKind::Mppt}, m, now);
      break;
    }
  }
}

// The fields the rows name, of either contract's sample, by the sample's address.
using Fields = std::map<std::string, double>;
template <class S>
Fields fields_of_status(const S& s) {
  return {{"generator_rpm", static_cast<double>(s.generator_rpm())}};
}
template <class S>
Fields fields_of_health(const S& s) {
  return {{"last_frame_age", s.last_frame_age()}};
}
template <class S>
Fields fields_of_battery(const S& s) {
  return {{"time_to_go", s.time_to_go()}, {"bms_state", static_cast<double>(s.bms_state())}};
}
template <class S>
Fields fields_of_mppt(const S& s) {
  return {{"mppt_state", static_cast<double>(s.mppt_state())},
          {"safety_enabled", static_cast<double>(s.safety_enabled())},
          {"pwm_enabled", static_cast<double>(s.pwm_enabled())},
          {"channel_3_active", static_cast<double>(s.channel_3_active())}};
}

// A reader of one topic in one contract, collecting the newest fields per device.
struct Collected {
  std::map<std::pair<Topic, int>, Fields> fields;
  template <class Sample>
  void take(DataReader& r, Topic t, Fields (*of)(const Sample&), int (*address)(const Sample&)) {
    Sample s;
    SampleInfo info;
    while (r.take_next_sample(&s, &info) == ReturnCode_t::RETCODE_OK)
      if (info.valid_data) fields[{t, address(s)}] = of(s);
  }
};

template <class S>
int address_key(const S& s) {
  return s.address();
}
template <class S>
int node_key(const S& s) {
  return s.node();
}
template <class S>
int device_key(const S& s) {
  return s.device();
}

// Both contracts' readers of the four topics on one client participant.
template <class Status, class StatusT, class Health, class HealthT, class Battery, class BatteryT, class Mppt,
          class MpptT>
struct Readers {
  explicit Readers(dds::DdsContext& c)
      : status(c.reader(c.topic(topics::kStatus, TypeSupport(new StatusT())), qos_profiles::kTelemetry)),
        health(c.reader(c.topic(topics::kHealth, TypeSupport(new HealthT())), qos_profiles::kState)),
        battery(c.reader(c.topic(topics::kBattery, TypeSupport(new BatteryT())), qos_profiles::kTelemetry)),
        mppt(c.reader(c.topic(topics::kMppt, TypeSupport(new MpptT())), qos_profiles::kTelemetry)) {}
  void take(Collected& out) {
    out.take<Status>(status, Topic::Status, &fields_of_status<Status>, &address_key<Status>);
    out.take<Health>(health, Topic::Health, &fields_of_health<Health>, &address_key<Health>);
    out.take<Battery>(battery, Topic::Battery, &fields_of_battery<Battery>, &node_key<Battery>);
    out.take<Mppt>(mppt, Topic::Mppt, &fields_of_mppt<Mppt>, &device_key<Mppt>);
  }
  DataReader& status;
  DataReader& health;
  DataReader& battery;
  DataReader& mppt;
};

bool same(double got, double want) { return std::isnan(want) ? std::isnan(got) : got == want; }

TEST(DdsNoValue, SentinelsAndValuesNotReceivedAreNaNAndThePreviousContractsAsItSentThem) {
  const int domain = pmu::test::exclusive_dds_domain();
  dds::DdsContext current_side(domain, "", "pmu-service-no-value");
  dds::DdsContext previous_side(domain, "", "pmu-service-no-value-previous", {}, dds::Transport::Default, {}, {}, {},
                                false, dds::contract_major() - 1);
  DdsPublisher current(current_side, 3s);
  DdsPublisher previous(previous_side, 3s);
  // A client of each contract: one participant has one topic of a name, of one type.
  dds::DdsContext client(domain, "", "reader-no-value");
  dds::DdsContext previous_client(domain, "", "reader-no-value-previous");
  Readers<pmu::v5::Status, pmu::v5::StatusPubSubType, pmu::v5::Health, pmu::v5::HealthPubSubType, pmu::v5::Battery,
          pmu::v5::BatteryPubSubType, pmu::v5::Mppt, pmu::v5::MpptPubSubType>
      now_readers(client);
  Readers<pmu::v4::Status, pmu::v4::StatusPubSubType, pmu::v4::Health, pmu::v4::HealthPubSubType, pmu::v4::Battery,
          pmu::v4::BatteryPubSubType, pmu::v4::Mppt, pmu::v4::MpptPubSubType>
      old_readers(previous_client);

  Collected now, old;
  auto all_read = [&](const Collected& c) {
    for (std::size_t i = 0; i < std::size(kRows); ++i)
      if (!c.fields.count({kRows[i].topic, address_of(i)})) return false;
    return true;
  };
  // Written again until read: a reader matched after a write does not get it (volatile telemetry).
  ASSERT_TRUE(pmu::test::wait_until(
      [&] {
        for (std::size_t i = 0; i < std::size(kRows); ++i) {
          report(current, kRows[i], address_of(i));
          report(previous, kRows[i], address_of(i));
        }
        now_readers.take(now);
        old_readers.take(old);
        return all_read(now) && all_read(old);
      },
      20s, 50ms))
      << now.fields.size() << " and " << old.fields.size() << " devices read";

  for (std::size_t i = 0; i < std::size(kRows); ++i) {
    const Row& r = kRows[i];
    SCOPED_TRACE(r.name);
    const double got = now.fields[{r.topic, address_of(i)}][r.field];
    const double got_previous = old.fields[{r.topic, address_of(i)}][r.field];
    EXPECT_TRUE(same(got, r.current)) << r.field << ": " << got << " in contract " << dds::contract_major()
                                      << ", expected " << r.current;
    EXPECT_TRUE(same(got_previous, r.previous)) << r.field << ": " << got_previous << " in contract "
                                                << dds::contract_major() - 1 << ", expected " << r.previous;
  }
}

}  // namespace
}  // namespace pmu::service::test
