#include "alarm_probe.hpp"

#include <fastdds/dds/core/status/SubscriptionMatchedStatus.hpp>
#include <fastdds/dds/subscriber/DataReaderListener.hpp>
#include <fastdds/dds/subscriber/SampleInfo.hpp>
#include <thread>

#include "pacer.hpp"
#include "pmu/idl/alarms.h"
#include "pmu/idl/alarmsPubSubTypes.h"
#include "pmu/idl/telemetry.h"
#include "pmu/idl/telemetryPubSubTypes.h"
#include "pmu/idl/topics.hpp"

namespace pmu::bench {

using namespace eprosima::fastdds::dds;

struct AlarmProbe::Listeners {
  struct Status : DataReaderListener {
    std::atomic<std::int64_t>* at;
    void on_data_available(DataReader* r) override {
      pmu::v5::Status s;
      SampleInfo info;
      while (r->take_next_sample(&s, &info) == ReturnCode_t::RETCODE_OK) {
        std::int64_t none = 0;
        if (info.valid_data && s.thermal_shutdown()) at->compare_exchange_strong(none, steady_ns());
      }
    }
  } status;
  struct Alarms : DataReaderListener {
    std::atomic<std::int64_t>* at;
    void on_data_available(DataReader* r) override {
      pmu::v5::Alarm a;
      SampleInfo info;
      while (r->take_next_sample(&a, &info) == ReturnCode_t::RETCODE_OK) {
        std::int64_t none = 0;
        if (info.valid_data && a.code().to_string() == "thermal_shutdown" &&
            a.state() == pmu::v5::ALARM_ACTIVE_UNACKNOWLEDGED)
          at->compare_exchange_strong(none, steady_ns());
      }
    }
  } alarms;
  DataReader* status_reader = nullptr;
  DataReader* alarm_reader = nullptr;
};

AlarmProbe::AlarmProbe(pmu::dds::DdsContext& dds) : dds_(dds), listeners_(new Listeners) {
  listeners_->status.at = &status_at_;
  listeners_->alarms.at = &alarm_at_;
  listeners_->status_reader = &dds_.reader(dds_.topic(topics::kStatus, TypeSupport(new pmu::v5::StatusPubSubType())),
                                           qos_profiles::kTelemetry, &listeners_->status);
  listeners_->alarm_reader = &dds_.reader(dds_.topic(topics::kAlarms, TypeSupport(new pmu::v5::AlarmPubSubType())),
                                          qos_profiles::kAlarms, &listeners_->alarms);
}

AlarmProbe::~AlarmProbe() {
  // The readers belong to the context, which outlives the probe; stop their callbacks first.
  listeners_->status_reader->set_listener(nullptr);
  listeners_->alarm_reader->set_listener(nullptr);
  delete listeners_;
}

void AlarmProbe::reset() noexcept {
  status_at_ = 0;
  alarm_at_ = 0;
}

bool AlarmProbe::wait_matched(std::chrono::milliseconds timeout) {
  const auto deadline = std::chrono::steady_clock::now() + timeout;
  while (std::chrono::steady_clock::now() < deadline) {
    SubscriptionMatchedStatus a, b;
    listeners_->status_reader->get_subscription_matched_status(a);
    listeners_->alarm_reader->get_subscription_matched_status(b);
    if (a.current_count > 0 && b.current_count > 0) return true;
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
  return false;
}

}  // namespace pmu::bench
