#include "telemetry_readers.hpp"

#include <fastdds/dds/core/status/SubscriptionMatchedStatus.hpp>
#include <fastdds/dds/subscriber/DataReaderListener.hpp>
#include <fastdds/dds/subscriber/SampleInfo.hpp>
#include <fastdds/dds/subscriber/Subscriber.hpp>
#include <fastdds/dds/subscriber/qos/DataReaderQos.hpp>
#include <stdexcept>
#include <thread>

#include "pmu/idl/telemetry.h"
#include "pmu/idl/telemetryPubSubTypes.h"
#include "pmu/idl/topics.hpp"

namespace pmu::bench {

using namespace eprosima::fastdds::dds;

namespace {

template <class T>
class Counter final : public DataReaderListener {
 public:
  Counter(TelemetryReaders::Shared shared, bool track_units) : shared_(shared), track_units_(track_units) {}
  void on_data_available(DataReader* reader) override {
    T sample;
    SampleInfo info;
    while (reader->take_next_sample(&sample, &info) == ReturnCode_t::RETCODE_OK) {
      if (!info.valid_data) continue;
      shared_.received.fetch_add(1, std::memory_order_relaxed);
      if (track_units_ && !shared_.seen[sample.address()].exchange(true, std::memory_order_relaxed))
        shared_.units.fetch_add(1, std::memory_order_relaxed);
    }
  }

 private:
  TelemetryReaders::Shared shared_;
  bool track_units_;
};

}  // namespace

TelemetryReaders::TelemetryReaders(pmu::dds::DdsContext& dds, int max_units) : dds_(dds) {
  subscriber_ = dds.participant().create_subscriber(SUBSCRIBER_QOS_DEFAULT);
  DataReaderQos qos;
  if (!subscriber_ ||
      subscriber_->get_datareader_qos_from_profile(qos_profiles::kTelemetry, qos) != ReturnCode_t::RETCODE_OK)
    throw std::runtime_error("no telemetry reader profile in the QoS file");
  qos.resource_limits().max_instances = max_units;
  qos.resource_limits().max_samples_per_instance = 4;
  qos.resource_limits().max_samples = 4 * max_units;
  const Shared shared{received_, units_, seen_};
  const auto add = [&](const char* name, TypeSupport type, std::unique_ptr<DataReaderListener> listener) {
    auto* r = subscriber_->create_datareader(&dds.topic(name, type), qos, listener.get());
    if (!r) throw std::runtime_error(std::string("cannot create a reader of ") + name);
    listeners_.push_back(std::move(listener));
    readers_.push_back(r);
  };
  add(topics::kVoltages, TypeSupport(new pmu::v5::VoltagesPubSubType()),
      std::make_unique<Counter<pmu::v5::Voltages>>(shared, true));
  add(topics::kCurrents, TypeSupport(new pmu::v5::CurrentsPubSubType()),
      std::make_unique<Counter<pmu::v5::Currents>>(shared, false));
  add(topics::kBatteryEnergy, TypeSupport(new pmu::v5::BatteryEnergyPubSubType()),
      std::make_unique<Counter<pmu::v5::BatteryEnergy>>(shared, false));
  add(topics::kTemperatures, TypeSupport(new pmu::v5::TemperaturesPubSubType()),
      std::make_unique<Counter<pmu::v5::Temperatures>>(shared, false));
  add(topics::kStatus, TypeSupport(new pmu::v5::StatusPubSubType()),
      std::make_unique<Counter<pmu::v5::Status>>(shared, false));
}

TelemetryReaders::~TelemetryReaders() {
  for (auto* r : readers_) {
    r->set_listener(nullptr);
    subscriber_->delete_datareader(r);
  }
  dds_.participant().delete_subscriber(subscriber_);
}

bool TelemetryReaders::wait_matched(std::chrono::milliseconds timeout) {
  const auto until = std::chrono::steady_clock::now() + timeout;
  for (;;) {
    bool all = true;
    for (auto* r : readers_) {
      SubscriptionMatchedStatus s;
      r->get_subscription_matched_status(s);
      all = all && s.current_count > 0;
    }
    if (all) return true;
    if (std::chrono::steady_clock::now() >= until) return false;
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  }
}

bool TelemetryReaders::wait_units(std::size_t units, std::chrono::milliseconds timeout) const {
  const auto until = std::chrono::steady_clock::now() + timeout;
  while (units_seen() < units) {
    if (std::chrono::steady_clock::now() >= until) return false;
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
  return true;
}

}  // namespace pmu::bench
