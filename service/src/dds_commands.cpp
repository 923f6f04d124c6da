#include "pmu/service/dds_commands.hpp"

#include <fastdds/dds/subscriber/DataReaderListener.hpp>
#include <fastdds/dds/subscriber/SampleInfo.hpp>
#include <spdlog/spdlog.h>

#include <chrono>
#include <mutex>
#include <sstream>

#include "pmu/idl/command.h"
#include "pmu/idl/commandPubSubTypes.h"
#include "pmu/idl/topics.hpp"
#include "pmu/service/command_cdr.hpp"
#include "pmu/service/command_service.hpp"
#include "pmu/service/dds_publisher.hpp"

namespace pmu::service {
namespace {

using namespace eprosima::fastdds::dds;

static_assert(static_cast<int>(pmu::GET_FIRMWARE) == static_cast<int>(CommandKind::GetFirmware));
static_assert(static_cast<int>(pmu::IN_PROGRESS) == static_cast<int>(CommandResult::InProgress));

constexpr std::chrono::seconds kMalformedLogInterval{10};

std::string guid_of(const SampleInfo& info) {
  std::ostringstream who;
  who << info.sample_identity.writer_guid();
  return who.str();
}

}  // namespace

struct DdsCommandEndpoint::Impl final : public DataReaderListener {
  dds::DdsContext& dds;
  DataWriter* writer = nullptr;
  DataReader* reader = nullptr;
  CommandSampleType* type = nullptr;  // owned by the TypeSupport registered with the participant
  // Held while a callback runs and while stop() detaches the service: once stop() returns,
  // no callback is inside, or will enter, the service.
  std::mutex service_mutex;
  CommandService* service = nullptr;
  std::mutex write_mutex;
  DdsPublisher* failures = nullptr;
  std::uint64_t malformed_logged = 0;
  std::chrono::steady_clock::time_point next_malformed_log{};

  Impl(dds::DdsContext& d, DdsPublisher* f) : dds(d), failures(f) {}

  void on_data_available(DataReader* r) override {
    std::lock_guard<std::mutex> lock(service_mutex);
    if (!service) return;
    CommandSampleType::Received received;
    SampleInfo info;
    while (r->take_next_sample(&received, &info) == ReturnCode_t::RETCODE_OK) {
      // Fast DDS 2.9 drops a sample whose deserialize failed before take sees it; a library
      // that hands it over anyway gives an empty Received. Either way it was counted.
      if (!info.valid_data || !received.sample) continue;
      received.sample->sender = guid_of(info);
      service->submit(*received.sample);
    }
    report_malformed();
  }

  // A payload that is not a pmu::Command cannot be answered (it has no readable request id):
  // counted by the type, logged at most every few seconds so a flood cannot fill the journal.
  void report_malformed() {
    const auto total = type->malformed();
    const auto now = std::chrono::steady_clock::now();
    if (total == malformed_logged || now < next_malformed_log) return;
    next_malformed_log = now + kMalformedLogInterval;
    spdlog::warn("pmu/command: dropped {} sample(s) that are not a pmu::Command as idl/command.idl defines it "
                 "({} since start); no reply is possible without a readable request_id",
                 total - malformed_logged, total);
    malformed_logged = total;
  }

  void publish(const CommandReplyData& d) {
    pmu::CommandReply s;
    s.request_id(d.request_id.substr(0, kMaxRequestIdLength));
    s.bus(d.bus.substr(0, kMaxBusNameLength));
    s.address(d.address);
    s.kind(static_cast<pmu::CommandKind>(static_cast<int>(d.kind)));
    s.result(static_cast<pmu::CommandResult>(static_cast<int>(d.result)));
    s.reason(d.reason.substr(0, 255));
    s.has_value(d.has_value);
    s.value(d.value);
    s.value_text(d.value_text.substr(0, 63));
    bool ok = false;
    {
      std::lock_guard<std::mutex> lock(write_mutex);
      ok = writer->write(&s);
    }
    if (!ok && failures)
      failures->count_failed_write(topics::kCommandReply, DeviceKey{d.bus, d.address}, "reply not sent");
  }
};

DdsCommandEndpoint::DdsCommandEndpoint(dds::DdsContext& dds, DdsPublisher* failures)
    : impl_(std::make_unique<Impl>(dds, failures)) {
  impl_->writer = &dds.writer(dds.topic(topics::kCommandReply, TypeSupport(new pmu::CommandReplyPubSubType())),
                              qos_profiles::kCommand);
}

DdsCommandEndpoint::~DdsCommandEndpoint() { stop(); }

void DdsCommandEndpoint::stop() {
  {
    std::lock_guard<std::mutex> lock(impl_->service_mutex);  // waits for a callback inside
    impl_->service = nullptr;
  }
  // Outside the lock: Fast DDS may wait here for a callback that waits for the lock.
  if (impl_->reader) impl_->reader->set_listener(nullptr);
}

void DdsCommandEndpoint::start(CommandService& service) {
  {
    std::lock_guard<std::mutex> lock(impl_->service_mutex);
    impl_->service = &service;
  }
  auto* type = new CommandSampleType();
  impl_->type = type;
  impl_->reader = &impl_->dds.reader(impl_->dds.topic(topics::kCommand, TypeSupport(type)), qos_profiles::kCommand,
                                     impl_.get());
}

void DdsCommandEndpoint::publish(const CommandReplyData& reply) { impl_->publish(reply); }

std::uint64_t DdsCommandEndpoint::malformed() const noexcept { return impl_->type ? impl_->type->malformed() : 0; }

}  // namespace pmu::service
