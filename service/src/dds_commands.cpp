#include "pmu/service/dds_commands.hpp"

#include <fastdds/dds/subscriber/DataReaderListener.hpp>
#include <fastdds/dds/subscriber/SampleInfo.hpp>
#include <mutex>
#include <sstream>

#include "pmu/idl/command.h"
#include "pmu/idl/commandPubSubTypes.h"
#include "pmu/idl/topics.hpp"
#include "pmu/service/command_service.hpp"

namespace pmu::service {
namespace {

using namespace eprosima::fastdds::dds;

static_assert(static_cast<int>(pmu::GET_FIRMWARE) == static_cast<int>(CommandKind::GetFirmware));
static_assert(static_cast<int>(pmu::IN_PROGRESS) == static_cast<int>(CommandResult::InProgress));

CommandRequest from_dds(const pmu::Command& c, const SampleInfo& info) {
  CommandRequest r;
  r.request_id = c.request_id().to_string();
  std::ostringstream who;
  who << info.sample_identity.writer_guid();
  r.sender = who.str();
  r.bus = c.bus().to_string();
  r.address = c.address();
  r.kind = static_cast<CommandKind>(static_cast<int>(c.kind()));
  r.parameter = c.parameter().to_string();
  r.value = c.value();
  r.outputs = c.outputs();
  r.enable = c.enable();
  r.groups = c.groups();
  if (c.expires_at() != 0)
    r.expires_at = std::chrono::system_clock::time_point(
        std::chrono::duration_cast<std::chrono::system_clock::duration>(std::chrono::nanoseconds(c.expires_at())));
  r.confirm = c.confirm();
  return r;
}

}  // namespace

struct DdsCommandEndpoint::Impl final : public DataReaderListener {
  dds::DdsContext& dds;
  DataWriter* writer = nullptr;
  DataReader* reader = nullptr;
  CommandService* service = nullptr;
  std::mutex write_mutex;
  std::uint64_t write_failures = 0;

  explicit Impl(dds::DdsContext& d) : dds(d) {}

  void on_data_available(DataReader* r) override {
    pmu::Command c;
    SampleInfo info;
    while (r->take_next_sample(&c, &info) == ReturnCode_t::RETCODE_OK) {
      if (!info.valid_data) continue;
      if (c.kind() > pmu::GET_FIRMWARE) {
        // An enum value from a newer client: still exactly one reply.
        CommandRequest bad = from_dds(c, info);
        bad.kind = CommandKind::Get;
        CommandReplyData d = make_reply(bad, CommandResult::Rejected, "unknown command kind");
        publish(d);
        continue;
      }
      service->submit(from_dds(c, info));
    }
  }

  void publish(const CommandReplyData& d) {
    pmu::CommandReply s;
    s.request_id(d.request_id);
    s.bus(d.bus);
    s.address(d.address);
    s.kind(static_cast<pmu::CommandKind>(static_cast<int>(d.kind)));
    s.result(static_cast<pmu::CommandResult>(static_cast<int>(d.result)));
    s.reason(d.reason.substr(0, 255));
    s.has_value(d.has_value);
    s.value(d.value);
    s.value_text(d.value_text.substr(0, 63));
    std::lock_guard<std::mutex> lock(write_mutex);
    if (!writer->write(&s)) ++write_failures;
  }
};

DdsCommandEndpoint::DdsCommandEndpoint(dds::DdsContext& dds) : impl_(std::make_unique<Impl>(dds)) {
  impl_->writer = &dds.writer(dds.topic(topics::kCommandReply, TypeSupport(new pmu::CommandReplyPubSubType())),
                              qos_profiles::kCommand);
}

DdsCommandEndpoint::~DdsCommandEndpoint() { stop(); }

void DdsCommandEndpoint::stop() {
  // No more callbacks into the service it feeds.
  if (impl_->reader) impl_->reader->set_listener(nullptr);
}

void DdsCommandEndpoint::start(CommandService& service) {
  impl_->service = &service;
  impl_->reader = &impl_->dds.reader(impl_->dds.topic(topics::kCommand, TypeSupport(new pmu::CommandPubSubType())),
                                     qos_profiles::kCommand, impl_.get());
}

void DdsCommandEndpoint::publish(const CommandReplyData& reply) { impl_->publish(reply); }

}  // namespace pmu::service
