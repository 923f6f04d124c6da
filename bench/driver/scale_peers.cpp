#include "scale_peers.hpp"

#include <atomic>
#include <cstdio>
#include <fastdds/dds/publisher/DataWriter.hpp>
#include <fastdds/dds/publisher/Publisher.hpp>
#include <fastdds/dds/publisher/qos/DataWriterQos.hpp>
#include <limits>
#include <stdexcept>
#include <thread>
#include <vector>

#include "pacer.hpp"
#include "pmu/dds/dds_context.hpp"
#include "pmu/idl/statePubSubTypes.h"
#include "pmu/idl/telemetry.h"
#include "pmu/idl/telemetryPubSubTypes.h"
#include "pmu/idl/topics.hpp"
#include "telemetry_readers.hpp"

namespace pmu::bench {

using namespace eprosima::fastdds::dds;

namespace {

template <class T>
void keyed(T& s, std::uint16_t address) {
  s.bus("fd3");  // the key (and so the size) of the service's samples in the benchmark
  s.address(address);
}

}  // namespace

int peer_telemetry(const PeerOptions& o) {
  StopFlag stop;
  pmu::dds::DdsContext dds(o.domain, o.qos_file, "bench-peer-telemetry", {}, o.transport);
  Publisher* publisher = dds.participant().create_publisher(PUBLISHER_QOS_DEFAULT);
  if (!publisher) throw std::runtime_error("cannot create a publisher");
  const auto writer = [&](const char* name, TypeSupport type, const char* profile) {
    DataWriterQos qos;
    if (publisher->get_datawriter_qos_from_profile(profile, qos) != ReturnCode_t::RETCODE_OK)
      throw std::runtime_error(std::string("no writer profile ") + profile);
    qos.resource_limits().max_instances = o.units;
    qos.resource_limits().max_samples_per_instance = 1;
    qos.resource_limits().max_samples = o.units;
    DataWriter* w = publisher->create_datawriter(&dds.topic(name, type), qos);
    if (!w) throw std::runtime_error(std::string("cannot create a writer of ") + name);
    return w;
  };
  DataWriter* voltages =
      writer(topics::kVoltages, TypeSupport(new pmu::v5::VoltagesPubSubType()), qos_profiles::kTelemetry);
  DataWriter* currents =
      writer(topics::kCurrents, TypeSupport(new pmu::v5::CurrentsPubSubType()), qos_profiles::kTelemetry);
  DataWriter* energy =
      writer(topics::kBatteryEnergy, TypeSupport(new pmu::v5::BatteryEnergyPubSubType()), qos_profiles::kTelemetry);
  DataWriter* temperatures =
      writer(topics::kTemperatures, TypeSupport(new pmu::v5::TemperaturesPubSubType()), qos_profiles::kTelemetry);
  DataWriter* status = writer(topics::kStatus, TypeSupport(new pmu::v5::StatusPubSubType()), qos_profiles::kTelemetry);
  (void)writer(topics::kConfig, TypeSupport(new pmu::v5::ConfigPubSubType()), qos_profiles::kState);
  (void)writer(topics::kInfo, TypeSupport(new pmu::v5::DeviceInfoPubSubType()), qos_profiles::kState);
  (void)writer(topics::kHealth, TypeSupport(new pmu::v5::HealthPubSubType()), qos_profiles::kState);

  pmu::v5::Voltages v;
  pmu::v5::Currents c;
  pmu::v5::BatteryEnergy e;
  pmu::v5::Temperatures t;
  pmu::v5::Status st;
  v.avionics(12.0f);
  c.avionics(1.5f);
  e.battery_a_mah(1200);
  t.internal(35.0f);
  st.generator_rpm(5200);
  // One round = every unit's five packets, as the fake PMUs stream them: rounds at
  // 1/period per second, each unit's packets back to back.
  paced(1.0 / o.period, std::numeric_limits<std::uint64_t>::max(), &stop.flag(), [&](std::uint64_t) {
    for (int a = 1; a <= o.units; ++a) {
      const auto address = static_cast<std::uint16_t>(a);
      keyed(v, address);
      keyed(c, address);
      keyed(e, address);
      keyed(t, address);
      keyed(st, address);
      voltages->write(&v);
      currents->write(&c);
      energy->write(&e);
      temperatures->write(&t);
      status->write(&st);
    }
  });
  return 0;
}

int peer_reader(const PeerOptions& o) {
  StopFlag stop;
  pmu::dds::DdsContext dds(o.domain, o.qos_file, "bench-peer-reader", {}, o.transport);
  TelemetryReaders readers(dds, 256);
  stop.wait();
  std::printf("peer-reader: %llu samples\n", static_cast<unsigned long long>(readers.received()));
  std::fflush(stdout);
  return 0;
}

}  // namespace pmu::bench
