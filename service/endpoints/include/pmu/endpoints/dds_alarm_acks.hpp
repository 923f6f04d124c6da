#pragma once
// The alarm acknowledgement topics on DDS: reads pmu/alarm_ack (QoS profile `command`) into an
// AlarmAckService and writes its replies to pmu/alarm_ack_reply. The only place that converts
// between pmu::v5::AlarmAck / AlarmAckReply and the service's own types.
//
// DDS-Security permissions made before these topics existed lack them: the endpoint then logs
// one error and the service runs without acknowledgements (active() is false), as
// DdsPublisher does for pmu/alarms.
//
// Lifetime and threads as DdsCommandEndpoint's: `dds` outlives the endpoint; the service given
// to start() outlives stop(); the listener runs on Fast DDS's threads and never lets an
// exception out; publish() from any thread.

#include <cstdint>
#include <memory>
#include <string>

#include "pmu/dds/dds_context.hpp"
#include "pmu/dispatch/alarm_ack_service.hpp"

namespace pmu::service {

class DdsAlarmAckEndpoint {
 public:
  DdsAlarmAckEndpoint(dds::DdsContext& dds, std::string vehicle);
  ~DdsAlarmAckEndpoint();
  // False when the permissions grant neither topic: nothing is read, nothing written.
  bool active() const noexcept;
  void start(AlarmAckService& service);
  // When it returns no callback is in, or will enter, the service. Idempotent.
  void stop();
  void publish(const AlarmAckReplyData& reply);
  // Acknowledgements written outside this vehicle's partition alone: not applied, not answered.
  std::uint64_t not_ours() const noexcept;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace pmu::service
