#pragma once
// pmu-mavlink's pmu/command writer and pmu/command_reply reader (interface.md 2.1, 2.3, 2.4):
// several commands in flight, polled on the program's loop (no listener runs on Fast DDS's
// threads). What a request id is for and when it is written again is RequestRoutes'
// (pmu::mavlink_commands); this holds each open request's sample to write it again with the
// same id, and takes the replies of this vehicle's service.
// Lifetime: the DdsContext outlives this. Threads: the loop only.
#include <fastdds/dds/publisher/DataWriter.hpp>
#include <fastdds/dds/subscriber/DataReader.hpp>

#include <chrono>
#include <cstdint>
#include <map>
#include <string>
#include <vector>

#include "pmu/command/command.hpp"
#include "pmu/dds/dds_context.hpp"
#include "pmu/idl/command.h"

namespace pmu::mavlink_bridge {

struct ServiceReply {
  std::string request_id;
  pmu::service::CommandResult result = pmu::service::CommandResult::Failed;
  std::string reason;
};

struct ServiceLinkCounters {
  std::uint64_t written = 0;
  std::uint64_t write_failures = 0;  // DDS refused a write: the owner's timeout answers it
  std::uint64_t other_vehicles = 0;  // a reply from another vehicle's service
};

class ServiceLink {
 public:
  using Clock = std::chrono::steady_clock;
  ServiceLink(pmu::dds::DdsContext& dds, std::string vehicle);

  // Writes `action` for the PMU at (bus, address) under `request_id`, expiring at `expires`
  // (steady); the sample is kept for write_again() until forget().
  void send(const std::string& request_id, const pmu::service::CommandAction& action, const std::string& bus,
            std::uint16_t address, bool confirm, Clock::time_point expires);
  // The same sample again, same id and expiry: a resend (interface.md 2.4).
  void write_again(const std::string& request_id);
  void forget(const std::string& request_id) { samples_.erase(request_id); }
  // Every reply of this vehicle's service waiting, in order.
  std::vector<ServiceReply> take();

  const ServiceLinkCounters& counters() const noexcept { return counters_; }

 private:
  void write(pmu::v5::Command& c);

  std::string vehicle_;
  eprosima::fastdds::dds::DataWriter& writer_;
  eprosima::fastdds::dds::DataReader& replies_;
  std::map<std::string, pmu::v5::Command> samples_;
  ServiceLinkCounters counters_;
};

}  // namespace pmu::mavlink_bridge
