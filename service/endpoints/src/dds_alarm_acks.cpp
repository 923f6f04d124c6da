#include "pmu/endpoints/dds_alarm_acks.hpp"

#include <fastdds/dds/subscriber/DataReaderListener.hpp>
#include <fastdds/dds/subscriber/SampleInfo.hpp>
#include <spdlog/spdlog.h>

#include <atomic>
#include <mutex>

#include "pmu/dds_settings/vehicle.hpp"
#include "pmu/dds/zero_padded_type.hpp"
#include "pmu/idl/alarms.h"
#include "pmu/idl/alarmsPubSubTypes.h"
#include "pmu/idl/guarded_type.hpp"
#include "pmu/idl/topics.hpp"
#include "pmu/session/log_throttle.hpp"
#include "writer_guid.hpp"

namespace pmu::service {
namespace {

using namespace eprosima::fastdds::dds;

// parse_alarm_ack reads the kind by AlarmSource's numbers, and the reply's state by AlarmState's.
static_assert(static_cast<int>(pmu::v5::SOURCE_BUS) == static_cast<int>(alarms::DeviceKind::Bus));
static_assert(static_cast<int>(pmu::v5::ALARM_CLEARED_UNACKNOWLEDGED) ==
              static_cast<int>(alarms::AlarmState::ClearedUnacknowledged));
static_assert(static_cast<int>(pmu::v5::ACK_REJECTED) == static_cast<int>(AckReplyResult::Rejected));

}  // namespace

struct DdsAlarmAckEndpoint::Impl final : public DataReaderListener {
  dds::DdsContext& dds;
  std::string vehicle;
  DataWriter* writer = nullptr;
  DataReader* reader = nullptr;
  std::mutex service_mutex;  // held while a callback runs and while stop() detaches the service
  AlarmAckService* service = nullptr;
  std::mutex write_mutex;
  std::atomic<std::uint64_t> not_ours{0};
  LogThrottle not_ours_reports{std::chrono::seconds(10)};
  idl::Guarded<pmu::v5::AlarmAckPubSubType>* type = nullptr;  // owned by the registered TypeSupport
  std::uint64_t malformed_logged = 0;
  LogThrottle malformed_reports{std::chrono::seconds(10)};

  Impl(dds::DdsContext& d, std::string v) : dds(d), vehicle(std::move(v)) {}

  void on_data_available(DataReader* r) override {
    // Whatever Fast DDS or the service does with a sample, nothing is thrown into its thread.
    try {
      take(r);
    } catch (const std::exception& e) {
      spdlog::error("pmu/alarm_ack: sample dropped: {}", e.what());
    } catch (...) {
      spdlog::error("pmu/alarm_ack: sample dropped");
    }
  }

  void take(DataReader* r) {
    std::lock_guard<std::mutex> lock(service_mutex);
    if (!service) return;
    pmu::v5::AlarmAck s;
    SampleInfo info;
    // A payload that does not deserialize is dropped by Fast DDS before take sees it: the type
    // is Guarded, because fastddsgen's own would throw out of every take, for ever, once one
    // such sample sat at the head of the history.
    while (r->take_next_sample(&s, &info) == ReturnCode_t::RETCODE_OK) {
      if (!info.valid_data) continue;
      AlarmAckSample sample{writer_guid_text(info),
                            s.request_id().to_string(),
                            s.vehicle().to_string(),
                            s.bus().to_string(),
                            static_cast<std::int64_t>(static_cast<std::uint32_t>(s.kind())),
                            s.device(),
                            s.code().to_string(),
                            s.expires_at()};
      const auto partitions = dds.remote_writers().partitions_of(info);
      if (partitions && dds::partitions_address_only(*partitions, vehicle)) {
        service->submit(sample);
        continue;
      }
      // As for commands: an acknowledgement not addressed to this vehicle alone is another
      // service's to answer.
      const auto total = not_ours.fetch_add(1, std::memory_order_relaxed) + 1;
      if (not_ours_reports.allow(LogThrottle::Clock::now()))
        spdlog::warn(
            "audit: alarm ack {} from {} was not written in this vehicle's partition alone: not applied, "
            "not answered ({} since start)",
            printable(sample.request_id), printable(sample.sender), total);
    }
    // Without a readable request id there is nothing to answer: counted, logged now and then
    // so a flood cannot fill the journal.
    const auto malformed = type ? type->malformed() : 0;
    if (malformed != malformed_logged && malformed_reports.allow(LogThrottle::Clock::now())) {
      spdlog::warn(
          "pmu/alarm_ack: dropped {} sample(s) that are not a pmu::v5::AlarmAck as idl/alarms.idl "
          "defines it ({} since start); no reply is possible without a readable request_id",
          malformed - malformed_logged, malformed);
      malformed_logged = malformed;
    }
  }

  void publish(const AlarmAckReplyData& d) {
    pmu::v5::AlarmAckReply s;
    s.request_id(d.request_id);
    s.vehicle(vehicle);
    s.bus(d.bus);
    s.kind(static_cast<pmu::v5::AlarmSource>(d.kind));
    s.device(d.device);
    s.code(d.code);
    s.result(static_cast<pmu::v5::AlarmAckResult>(d.result));
    s.reason(d.reason);
    s.state(static_cast<pmu::v5::AlarmState>(d.state));
    bool ok = false;
    {
      std::lock_guard<std::mutex> lock(write_mutex);
      ok = writer && writer->write(&s);
    }
    if (!ok) spdlog::warn("pmu/alarm_ack_reply: reply to {} not sent", printable(d.request_id));
  }
};

DdsAlarmAckEndpoint::DdsAlarmAckEndpoint(dds::DdsContext& dds, std::string vehicle)
    : impl_(std::make_unique<Impl>(dds, std::move(vehicle))) {
  try {
    impl_->writer = &dds.writer(dds.topic(topics::kAlarmAckReply, dds::zero_padded<pmu::v5::AlarmAckReplyPubSubType>()),
                                qos_profiles::kCommand);
  } catch (const dds::DdsError& e) {
    if (!dds.secure()) throw;
    spdlog::error(
        "{} and {} are not served, alarms cannot be acknowledged over DDS: {}; the DDS-Security "
        "permissions were made before they existed (deploy/security/make_pki.sh makes them with them)",
        topics::kAlarmAck, topics::kAlarmAckReply, e.what());
  }
}

DdsAlarmAckEndpoint::~DdsAlarmAckEndpoint() { stop(); }

bool DdsAlarmAckEndpoint::active() const noexcept { return impl_->writer != nullptr; }

void DdsAlarmAckEndpoint::start(AlarmAckService& service) {
  if (!impl_->writer) return;
  {
    std::lock_guard<std::mutex> lock(impl_->service_mutex);
    impl_->service = &service;
  }
  try {
    auto* type = new idl::Guarded<pmu::v5::AlarmAckPubSubType>();
    impl_->type = type;
    impl_->reader =
        &impl_->dds.reader(impl_->dds.topic(topics::kAlarmAck, TypeSupport(type)), qos_profiles::kCommand, impl_.get());
  } catch (const dds::DdsError& e) {
    if (!impl_->dds.secure()) throw;
    spdlog::error(
        "{} is not read, alarms cannot be acknowledged over DDS: {}; the DDS-Security permissions "
        "were made before it existed (deploy/security/make_pki.sh makes them with it)",
        topics::kAlarmAck, e.what());
  }
}

void DdsAlarmAckEndpoint::stop() {
  {
    std::lock_guard<std::mutex> lock(impl_->service_mutex);
    impl_->service = nullptr;
  }
  if (impl_->reader) impl_->reader->set_listener(nullptr);
}

void DdsAlarmAckEndpoint::publish(const AlarmAckReplyData& reply) { impl_->publish(reply); }

std::uint64_t DdsAlarmAckEndpoint::not_ours() const noexcept { return impl_->not_ours.load(std::memory_order_relaxed); }

}  // namespace pmu::service
