#include "program/service_link.hpp"

#include <fastdds/dds/subscriber/SampleInfo.hpp>
#include <fastdds/dds/topic/TypeSupport.hpp>

#include "pmu/dds/command_sample.hpp"
#include "pmu/idl/commandPubSubTypes.h"
#include "pmu/idl/guarded_type.hpp"
#include "pmu/idl/topics.hpp"

namespace pmu::mavlink_bridge {

namespace {
using eprosima::fastdds::dds::SampleInfo;
using eprosima::fastdds::dds::TypeSupport;
}  // namespace

ServiceLink::ServiceLink(pmu::dds::DdsContext& dds, std::string vehicle)
    : vehicle_(std::move(vehicle)),
      writer_(dds.writer(dds.topic(topics::kCommand, TypeSupport(new pmu::v5::CommandPubSubType())),
                         qos_profiles::kCommand)),
      replies_(
          dds.reader(dds.topic(topics::kCommandReply, TypeSupport(new idl::Guarded<pmu::v5::CommandReplyPubSubType>())),
                     qos_profiles::kCommand)) {}

void ServiceLink::write(pmu::v5::Command& c) {
  if (writer_.write(&c))  // bool in Fast DDS 2.x
    ++counters_.written;
  else
    ++counters_.write_failures;
}

void ServiceLink::send(const std::string& request_id, const pmu::service::CommandAction& action, const std::string& bus,
                       std::uint16_t address, bool confirm, Clock::time_point expires) {
  pmu::v5::Command c;
  c.request_id(request_id);
  c.vehicle(vehicle_);
  c.bus(bus);
  c.address(address);
  pmu::dds::put_action(action, c);
  c.expires_at(pmu::dds::epoch_ns_at(expires));
  c.confirm(confirm);
  auto& kept = samples_[request_id] = c;
  write(kept);
}

void ServiceLink::write_again(const std::string& request_id) {
  const auto it = samples_.find(request_id);
  if (it != samples_.end()) write(it->second);
}

std::vector<ServiceReply> ServiceLink::take() {
  std::vector<ServiceReply> out;
  pmu::v5::CommandReply r;
  SampleInfo info;
  while (replies_.take_next_sample(&r, &info) == ReturnCode_t::RETCODE_OK) {
    if (!info.valid_data) continue;
    if (r.vehicle().to_string() != vehicle_) {
      ++counters_.other_vehicles;
      continue;
    }
    out.push_back({r.request_id().to_string(), pmu::dds::command_result(r.result()), r.reason().to_string()});
  }
  return out;
}

}  // namespace pmu::mavlink_bridge
