#include "pmu/endpoints/dds_commands.hpp"

#include <fastdds/dds/subscriber/DataReaderListener.hpp>
#include <fastdds/dds/subscriber/SampleInfo.hpp>
#include <spdlog/spdlog.h>

#include <atomic>
#include <chrono>
#include <cstring>
#include <optional>
#include <map>
#include <mutex>
#include <vector>

#include "pmu/dds_settings/vehicle.hpp"
#include "pmu/dds/zero_padded_type.hpp"
#include "pmu/dispatch/command_service.hpp"
#include "pmu/endpoints/command_cdr.hpp"
#include "pmu/endpoints/dds_publisher.hpp"
#include "pmu/idl/command.h"
#include "pmu/idl/commandPubSubTypes.h"
#include "pmu/idl/guarded_type.hpp"
#include "pmu/idl/topics.hpp"
#include "pmu/session/log_throttle.hpp"
#include "writer_guid.hpp"

namespace pmu::service {
namespace {

using namespace eprosima::fastdds::dds;

static_assert(static_cast<int>(pmu::v5::GET_FIRMWARE) == static_cast<int>(CommandKind::GetFirmware));
static_assert(static_cast<int>(pmu::v5::IN_PROGRESS) == static_cast<int>(CommandResult::InProgress));

constexpr std::chrono::seconds kMalformedLogInterval{10};

std::string partition_list(const std::vector<std::string>& names) {
  if (names.empty()) return "the default partition";
  std::string out;
  for (const auto& n : names) out += (out.empty() ? "'" : ", '") + printable(n) + "'";
  return "partition(s) " + out;
}

// The reply topic's type: written zero-padded (zero_padded_type.hpp) and, for the standby's
// reader, read guarded (guarded_type.hpp): one type serves both, as a topic has one.
class ZeroPaddedCommandReply : public pmu::v5::CommandReplyPubSubType {
 public:
  bool serialize(void* data, eprosima::fastrtps::rtps::SerializedPayload_t* payload) override {
    std::memset(payload->data, 0, payload->max_size);
    return pmu::v5::CommandReplyPubSubType::serialize(data, payload);
  }
};
using CommandReplyTopicType = idl::Guarded<ZeroPaddedCommandReply>;

// A reply as another instance wrote it, in the service's terms; nullopt for values outside the
// IDL's enums (no instance of this service writes them).
std::optional<CommandReplyData> peer_reply_data(const pmu::v5::CommandReply& s) {
  const auto kind = static_cast<std::uint32_t>(s.kind());
  const auto result = static_cast<std::uint32_t>(s.result());
  if (kind >= kCommandKindCount || result > static_cast<std::uint32_t>(CommandResult::InProgress)) return std::nullopt;
  CommandReplyData d;
  d.request_id = s.request_id();
  d.bus = s.bus();
  d.address = s.address();
  d.kind = static_cast<CommandKind>(kind);
  d.result = static_cast<CommandResult>(result);
  d.reason = s.reason();
  d.has_value = s.has_value();
  d.value = s.value();
  d.value_text = s.value_text();
  return d;
}

}  // namespace

struct DdsCommandEndpoint::Impl final : public DataReaderListener {
  dds::DdsContext& dds;
  std::string vehicle;
  std::atomic<std::uint64_t> not_ours{0};  // commands for another vehicle or from another partition
  // (the rate limit below is used under service_mutex)
  LogThrottle not_ours_reports{kMalformedLogInterval};
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

  Impl(dds::DdsContext& d, DdsPublisher* f, std::string v) : dds(d), vehicle(std::move(v)), failures(f) {}

  // Only this vehicle's commands are answered: a command for another vehicle is that
  // vehicle's service's to answer, and one from a writer outside this vehicle's partition
  // (a pattern such as "*" reaches every vehicle) is not addressed to this vehicle alone.
  // `partitions`: those the sample's writer announced (RemoteWriters); a writer discovery
  // never reported cannot be judged, so its commands are not taken either.
  bool ours(const CommandSample& s, const std::optional<std::vector<std::string>>& partitions) {
    std::string why;
    if (s.vehicle != vehicle) {
      why = "is for vehicle '" + printable(s.vehicle) + "'";
    } else if (!partitions) {
      why = "came from a writer discovery never reported (its partitions are unknown)";
    } else if (!dds::partitions_address_only(*partitions, vehicle)) {
      why = "was written in " + partition_list(*partitions) + ", not in " +
            partition_list(dds::vehicle_partitions(vehicle)) + " alone";
    } else {
      return true;
    }
    const auto total = not_ours.fetch_add(1, std::memory_order_relaxed) + 1;
    if (const auto held = not_ours_reports.allow(LogThrottle::Clock::now()))
      spdlog::warn(
          "audit: command {} from {} {}; this service is vehicle '{}': not executed, not answered "
          "({} such command(s) since start{})",
          printable(s.request_id), printable(s.sender), why, printable(vehicle), total,
          *held ? ", " + std::to_string(*held) + " not logged since the last message" : std::string());
    return false;
  }

  // The bus owner's replies, read on the standby (follow_peer_replies). Its own lock and its
  // own pointer to the service, never service_mutex: the command listener holds that lock
  // while it writes a reply, and Fast DDS may deliver the reply to this participant's own
  // reader, on the writing thread or on a receive thread that the write then waits for.
  // This instance's own replies are dropped before any lock is taken.
  struct PeerReplies final : public DataReaderListener {
    Impl& impl;
    // Held while a callback hands replies to the service and while stop() detaches it.
    std::mutex mutex;
    CommandService* service = nullptr;
    explicit PeerReplies(Impl& i) : impl(i) {}
    void on_data_available(DataReader* r) override {
      const auto own = impl.dds.participant().guid().guidPrefix;
      std::vector<CommandReplyData> peers;
      pmu::v5::CommandReply reply;
      SampleInfo info;
      while (r->take_next_sample(&reply, &info) == ReturnCode_t::RETCODE_OK) {
        // This instance's own replies are no peer's; another vehicle's are another pair's.
        if (!info.valid_data || info.sample_identity.writer_guid().guidPrefix == own) continue;
        if (reply.vehicle() != impl.vehicle) continue;
        if (auto d = peer_reply_data(reply)) peers.push_back(std::move(*d));
      }
      if (peers.empty()) return;
      std::lock_guard<std::mutex> lock(mutex);
      if (!service) return;
      for (const auto& d : peers) service->peer_reply(d);
    }
  };
  PeerReplies peer_replies{*this};
  DataReader* reply_reader = nullptr;

  void on_data_available(DataReader* r) override {
    std::lock_guard<std::mutex> lock(service_mutex);
    if (!service) return;
    CommandSampleType::Received received;
    SampleInfo info;
    while (r->take_next_sample(&received, &info) == ReturnCode_t::RETCODE_OK) {
      // Fast DDS 2.9 drops a sample whose deserialize failed before take sees it; a library
      // that hands it over anyway gives an empty Received. Either way it was counted.
      if (!info.valid_data || !received.sample) continue;
      received.sample->sender = writer_guid_text(info);
      if (ours(*received.sample, dds.remote_writers().partitions_of(info))) service->submit(*received.sample);
    }
    report_malformed();
  }

  // A payload that is not a pmu::v5::Command cannot be answered (it has no readable request id):
  // counted by the type, logged at most every few seconds so a flood cannot fill the journal.
  void report_malformed() {
    const auto total = type->malformed();
    const auto now = std::chrono::steady_clock::now();
    if (total == malformed_logged || now < next_malformed_log) return;
    next_malformed_log = now + kMalformedLogInterval;
    spdlog::warn(
        "pmu/command: dropped {} sample(s) that are not a pmu::v5::Command as idl/command.idl defines it "
        "({} since start); no reply is possible without a readable request_id",
        total - malformed_logged, total);
    malformed_logged = total;
  }

  void publish(const CommandReplyData& d) {
    pmu::v5::CommandReply s;
    s.request_id(d.request_id.substr(0, kMaxRequestIdLength));
    s.vehicle(vehicle);
    s.bus(d.bus.substr(0, kMaxBusNameLength));
    s.address(d.address);
    s.kind(static_cast<pmu::v5::CommandKind>(static_cast<int>(d.kind)));
    s.result(static_cast<pmu::v5::CommandResult>(static_cast<int>(d.result)));
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

DdsCommandEndpoint::DdsCommandEndpoint(dds::DdsContext& dds, DdsPublisher* failures, std::string vehicle)
    : impl_(std::make_unique<Impl>(dds, failures, std::move(vehicle))) {
  impl_->writer =
      &dds.writer(dds.topic(topics::kCommandReply, TypeSupport(new CommandReplyTopicType())), qos_profiles::kCommand);
}

void DdsCommandEndpoint::stop() {
  {
    std::lock_guard<std::mutex> lock(impl_->service_mutex);  // waits for a callback inside
    impl_->service = nullptr;
  }
  {
    std::lock_guard<std::mutex> lock(impl_->peer_replies.mutex);
    impl_->peer_replies.service = nullptr;
  }
  // Outside the lock: Fast DDS may wait here for a callback that waits for the lock.
  if (impl_->reader) impl_->reader->set_listener(nullptr);
  if (impl_->reply_reader) impl_->reply_reader->set_listener(nullptr);
}

DdsCommandEndpoint::~DdsCommandEndpoint() { stop(); }

void DdsCommandEndpoint::start(CommandService& service) {
  {
    std::lock_guard<std::mutex> lock(impl_->service_mutex);
    impl_->service = &service;
  }
  auto* type = new CommandSampleType();
  impl_->type = type;
  impl_->reader =
      &impl_->dds.reader(impl_->dds.topic(topics::kCommand, TypeSupport(type)), qos_profiles::kCommand, impl_.get());
}

void DdsCommandEndpoint::follow_peer_replies() {
  {
    std::lock_guard<std::mutex> lock(impl_->peer_replies.mutex);
    std::lock_guard<std::mutex> service_lock(impl_->service_mutex);
    impl_->peer_replies.service = impl_->service;
  }
  impl_->reply_reader =
      &impl_->dds.reader(impl_->dds.topic(topics::kCommandReply, TypeSupport(new CommandReplyTopicType())),
                         qos_profiles::kCommand, &impl_->peer_replies);
}

void DdsCommandEndpoint::publish(const CommandReplyData& reply) { impl_->publish(reply); }

std::uint64_t DdsCommandEndpoint::not_ours() const noexcept { return impl_->not_ours.load(std::memory_order_relaxed); }

std::uint64_t DdsCommandEndpoint::malformed() const noexcept { return impl_->type ? impl_->type->malformed() : 0; }

}  // namespace pmu::service
