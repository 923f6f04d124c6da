#include "pmu/endpoints/dds_role.hpp"

#include <fastdds/dds/subscriber/DataReaderListener.hpp>
#include <fastdds/dds/subscriber/SampleInfo.hpp>
#include <spdlog/spdlog.h>

#include <atomic>
#include <cstring>
#include <deque>
#include <mutex>
#include <utility>
#include <vector>

#include "pmu/command/command.hpp"
#include "pmu/dds/role_sample.hpp"
#include "pmu/dds/zero_padded_type.hpp"
#include "pmu/dds_settings/vehicle.hpp"
#include "pmu/idl/guarded_type.hpp"
#include "pmu/idl/role.h"
#include "pmu/idl/rolePubSubTypes.h"
#include "pmu/idl/topics.hpp"
#include "pmu/session/log_throttle.hpp"
#include "writer_guid.hpp"

namespace pmu::service {
namespace role_endpoint {

using namespace eprosima::fastdds::dds;

// pmu/role is written and read on one participant, so its one topic's type does both: samples
// serialized into a cleared buffer (zero_padded_type.hpp says why) and a payload that does not
// deserialize counted and dropped rather than thrown into Fast DDS (guarded_type.hpp).
class RoleHeartbeatType final : public pmu::v5::RoleHeartbeatPubSubType {
 public:
  bool serialize(void* data, eprosima::fastrtps::rtps::SerializedPayload_t* payload) override {
    std::memset(payload->data, 0, payload->max_size);
    return RoleHeartbeatPubSubType::serialize(data, payload);
  }
  bool deserialize(eprosima::fastrtps::rtps::SerializedPayload_t* payload, void* data) override {
    try {
      if (RoleHeartbeatPubSubType::deserialize(payload, data)) return true;
    } catch (...) {  // whatever Fast CDR throws: the payload is not this type
    }
    *static_cast<pmu::v5::RoleHeartbeat*>(data) = pmu::v5::RoleHeartbeat();
    undecodable.fetch_add(1, std::memory_order_relaxed);
    return false;
  }
  std::atomic<std::uint64_t> undecodable{0};
};

// The replies of the last requests, so a resend is answered as the first time.
constexpr std::size_t kRememberedMoves = 64;

struct Answered {
  std::string sender;
  std::string request_id;
  redundancy::MoveResult result;
};

}  // namespace role_endpoint

using namespace eprosima::fastdds::dds;

struct DdsRoleEndpoint::Impl {
  dds::DdsContext& dds;
  std::string vehicle;
  Clocks clocks;
  std::string name;  // the instance moves must name
  ReportFn report_fn;
  MoveFn move_fn;
  role_endpoint::RoleHeartbeatType* role_type = nullptr;  // owned by the registered TypeSupport
  Topic* role_topic = nullptr;
  DataWriter* role_writer = nullptr;
  DataWriter* reply_writer = nullptr;
  DataReader* role_reader = nullptr;
  DataReader* move_reader = nullptr;
  std::mutex callback_mutex;  // held while a callback runs and while stop() detaches them
  bool running = false;
  std::mutex role_write_mutex;   // the heartbeat's writer
  std::mutex reply_write_mutex;  // a move's reply, written by a callback
  std::atomic<std::uint64_t> own{0}, not_ours{0}, malformed{0}, expired{0};
  LogThrottle malformed_reports{std::chrono::seconds(10)};
  std::atomic<std::uint64_t> malformed_seen{0};  // the type's undecodable count last added to `malformed`
  std::deque<role_endpoint::Answered> answered;  // under callback_mutex

  struct RoleListener final : DataReaderListener {
    Impl* impl = nullptr;
    void on_data_available(DataReader* r) override {
      impl->guard("pmu/role", [&] { impl->take_roles(r); });
    }
  } role_listener;
  struct MoveListener final : DataReaderListener {
    Impl* impl = nullptr;
    void on_data_available(DataReader* r) override {
      impl->guard("pmu/role_move", [&] { impl->take_moves(r); });
    }
  } move_listener;

  Impl(dds::DdsContext& d, std::string v, Clocks c) : dds(d), vehicle(std::move(v)), clocks(std::move(c)) {
    role_listener.impl = this;
    move_listener.impl = this;
  }

  // Whatever Fast DDS or the holder does with a sample, nothing is thrown into its thread.
  template <class F>
  void guard(const char* topic, F&& f) {
    try {
      f();
    } catch (const std::exception& e) {
      spdlog::error("{}: sample dropped: {}", topic, e.what());
    } catch (...) {
      spdlog::error("{}: sample dropped", topic);
    }
  }

  bool own_sample(const SampleInfo& info) {
    return info.sample_identity.writer_guid().guidPrefix == dds.participant().guid().guidPrefix;
  }

  // The samples are taken before callback_mutex, and this instance's own dropped there: a
  // heartbeat comes back to this reader on the thread that writes it, inside write() (Fast
  // DDS's delivery within a process), and a peer's sample taken in the same call makes that
  // thread wait for callback_mutex while it holds role_write_mutex. So no callback holds
  // role_write_mutex: a move's reply has its own.
  void take_roles(DataReader* r) {
    std::vector<std::pair<redundancy::RoleReport, std::chrono::steady_clock::time_point>> reports;
    std::vector<std::string> problems;
    pmu::v5::RoleHeartbeat s;
    SampleInfo info;
    while (r->take_next_sample(&s, &info) == ReturnCode_t::RETCODE_OK) {
      if (!info.valid_data) continue;
      const auto arrived = clocks.steady();
      if (own_sample(info)) {
        own.fetch_add(1, std::memory_order_relaxed);
        continue;
      }
      const auto read = dds::read_role_heartbeat(s);
      if (!read.ok()) {
        malformed.fetch_add(1, std::memory_order_relaxed);
        problems.push_back(read.problem + " (from " + printable(writer_guid_text(info)) + ")");
        continue;
      }
      if (read.vehicle != vehicle) {
        not_ours.fetch_add(1, std::memory_order_relaxed);
        continue;
      }
      reports.emplace_back(read.report, arrived);
    }
    const auto undecodable = role_type ? role_type->undecodable.load(std::memory_order_relaxed) : 0;
    if (reports.empty() && problems.empty() && undecodable == malformed_seen.load(std::memory_order_relaxed)) return;
    std::lock_guard<std::mutex> lock(callback_mutex);
    for (const auto& p : problems) report_malformed(p);
    if (running && report_fn)
      for (const auto& [report, arrived] : reports) report_fn(report, arrived);
    // A payload that is not a RoleHeartbeat at all never reaches take: counted by its type.
    const auto before = malformed_seen.exchange(undecodable, std::memory_order_relaxed);
    if (undecodable != before) {
      malformed.fetch_add(undecodable - before, std::memory_order_relaxed);
      report_malformed("a payload that is not a pmu::v5::RoleHeartbeat as idl/role.idl defines it");
    }
  }

  void report_malformed(const std::string& what) {
    if (malformed_reports.allow(LogThrottle::Clock::now()))
      spdlog::warn("pmu/role: sample dropped: {} ({} dropped since start)", what,
                   malformed.load(std::memory_order_relaxed));
  }

  // A move's reply is written under callback_mutex (so that stop() waits for it) and under
  // reply_write_mutex, which the heartbeat's writer never holds (take_roles says why).
  void take_moves(DataReader* r) {
    std::lock_guard<std::mutex> lock(callback_mutex);
    pmu::v5::RoleMove s;
    SampleInfo info;
    while (r->take_next_sample(&s, &info) == ReturnCode_t::RETCODE_OK) {
      if (!info.valid_data || !running || !move_fn) continue;
      if (s.vehicle().to_string() != vehicle || s.instance().to_string() != name) continue;  // the peer's
      const auto partitions = dds.remote_writers().partitions_of(info);
      redundancy::MoveRequest request{s.request_id().to_string(), s.instance().to_string(), s.requester().to_string()};
      const std::string sender = writer_guid_text(info);
      // As commands: a request not written in this vehicle's partition alone may reach every
      // vehicle's instances at once.
      if (!partitions || !dds::partitions_address_only(*partitions, vehicle)) {
        not_ours.fetch_add(1, std::memory_order_relaxed);
        spdlog::warn(
            "audit: role move {} from {} ({}) was not written in this vehicle's partition alone: not moved, "
            "not answered",
            printable(request.request_id), printable(request.requester), printable(sender));
        continue;
      }
      if (s.expires_at() != 0 && s.expires_at() < clocks.wall_ns()) {
        expired.fetch_add(1, std::memory_order_relaxed);
        spdlog::warn("audit: role move {} from {} ({}) expired before it arrived: not moved, not answered",
                     printable(request.request_id), printable(request.requester), printable(sender));
        continue;
      }
      redundancy::MoveResult result;
      bool resend = false;
      for (const auto& a : answered)
        if (a.sender == sender && a.request_id == request.request_id) {
          result = a.result;
          resend = true;
        }
      if (!resend) {
        result = move_fn(request);
        answered.push_back({sender, request.request_id, result});
        if (answered.size() > role_endpoint::kRememberedMoves) answered.pop_front();
        spdlog::info("audit: role move {} from {} ({}) -> {}{}{}", printable(request.request_id),
                     printable(request.requester), printable(sender), result.accepted ? "accepted" : "refused",
                     result.reason.empty() ? "" : ": ", printable(result.reason));
      }
      reply(request, result);
    }
  }

  void reply(const redundancy::MoveRequest& request, const redundancy::MoveResult& result) {
    pmu::v5::RoleMoveReply s;
    s.request_id(request.request_id);
    s.vehicle(vehicle);
    s.instance(name);
    s.accepted(result.accepted);
    s.reason(result.reason.substr(0, 127));
    bool ok = false;
    {
      std::lock_guard<std::mutex> lock(reply_write_mutex);
      ok = reply_writer && reply_writer->write(&s);
    }
    if (!ok) spdlog::warn("pmu/role_move_reply: reply to {} not sent", printable(request.request_id));
  }
};

DdsRoleEndpoint::DdsRoleEndpoint(dds::DdsContext& dds, std::string vehicle, Clocks clocks)
    : impl_(std::make_unique<Impl>(dds, std::move(vehicle), std::move(clocks))) {
  auto* type = new role_endpoint::RoleHeartbeatType();
  impl_->role_type = type;
  impl_->role_topic = &dds.topic(topics::kRole, TypeSupport(type));
  impl_->role_writer = &dds.writer(*impl_->role_topic, qos_profiles::kRole);
  impl_->reply_writer = &dds.writer(
      dds.topic(topics::kRoleMoveReply, dds::zero_padded<pmu::v5::RoleMoveReplyPubSubType>()), qos_profiles::kCommand);
}

DdsRoleEndpoint::~DdsRoleEndpoint() { stop(); }

void DdsRoleEndpoint::on_report(ReportFn fn) { impl_->report_fn = std::move(fn); }

void DdsRoleEndpoint::on_move(std::string name, MoveFn fn) {
  impl_->name = std::move(name);
  impl_->move_fn = std::move(fn);
}

void DdsRoleEndpoint::start() {
  {
    std::lock_guard<std::mutex> lock(impl_->callback_mutex);
    impl_->running = true;
  }
  if (impl_->report_fn && !impl_->role_reader)
    impl_->role_reader = &impl_->dds.reader(*impl_->role_topic, qos_profiles::kRole, &impl_->role_listener);
  if (impl_->move_fn && !impl_->move_reader)
    impl_->move_reader = &impl_->dds.reader(
        impl_->dds.topic(topics::kRoleMove, TypeSupport(new idl::Guarded<pmu::v5::RoleMovePubSubType>())),
        qos_profiles::kCommand, &impl_->move_listener);
}

void DdsRoleEndpoint::stop() {
  {
    std::lock_guard<std::mutex> lock(impl_->callback_mutex);
    impl_->running = false;
  }
  if (impl_->role_reader) impl_->role_reader->set_listener(nullptr);
  if (impl_->move_reader) impl_->move_reader->set_listener(nullptr);
}

bool DdsRoleEndpoint::publish(const redundancy::RoleReport& report) {
  auto sample = dds::role_heartbeat_sample(impl_->vehicle, report);
  bool ok = false;
  {
    std::lock_guard<std::mutex> lock(impl_->role_write_mutex);
    ok = impl_->role_writer->write(&sample);
  }
  if (!ok) spdlog::warn("pmu/role: heartbeat of {} not written", printable(report.name));
  return ok;
}

std::uint64_t DdsRoleEndpoint::own() const noexcept { return impl_->own.load(std::memory_order_relaxed); }
std::uint64_t DdsRoleEndpoint::not_ours() const noexcept { return impl_->not_ours.load(std::memory_order_relaxed); }
std::uint64_t DdsRoleEndpoint::malformed() const noexcept { return impl_->malformed.load(std::memory_order_relaxed); }
std::uint64_t DdsRoleEndpoint::expired() const noexcept { return impl_->expired.load(std::memory_order_relaxed); }

}  // namespace pmu::service
