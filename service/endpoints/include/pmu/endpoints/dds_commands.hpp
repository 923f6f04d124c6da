#pragma once
// The command topics on DDS: reads pmu/command (QoS profile `command`) into the
// CommandService and writes every reply to pmu/command_reply. The only place that converts
// between pmu::v5::Command / pmu::v5::CommandReply and the service's own command types: samples are
// read field for field as they arrived (command_cdr.hpp) and parsed by CommandService, so
// no payload a peer can send reaches Fast DDS's threads as an exception.
//
// Lifetime: `dds` and `failures` must outlive the endpoint, which keeps a reference and a
// pointer; the service given to start() must outlive the stop() call (or the destructor,
// which calls it). main.cpp destroys the endpoint after the CommandService whose ReplyFn
// calls publish(), and stops it first.
// Threads: start() and stop() on one thread (main.cpp's main thread); the reader's listener
// runs on Fast DDS's threads and calls CommandService::submit() there; publish() from any
// thread (a mutex serialises the writer); malformed() and not_ours() from any thread.
// With follow_peer_replies(), a second reader's listener runs on Fast DDS's threads and calls
// CommandService::peer_reply() there, under a detach guard of its own (stop() detaches both):
// the command listener holds its guard while it writes a reply, which this reader may receive.

#include <memory>
#include <string>

#include "pmu/command/command.hpp"
#include "pmu/dds/dds_context.hpp"

namespace pmu::service {

class CommandService;
class DdsPublisher;

class DdsCommandEndpoint {
 public:
  // Creates the reply writer. Throws dds::DdsError at start-up. A reply Fast DDS refuses is
  // counted and logged through `failures` (pmu/health's publish_failures) when given.
  // Only commands for `vehicle` (vehicle.hpp), written in its partition alone, are executed
  // and answered; others are logged (rate-limited) and counted in not_ours().
  explicit DdsCommandEndpoint(dds::DdsContext& dds, DdsPublisher* failures = nullptr, std::string vehicle = {});
  ~DdsCommandEndpoint();
  // Starts reading commands into `service` (which must outlive this endpoint's reader).
  void start(CommandService& service);
  // Hot standby (design.md "Hot standby"): also reads pmu/command_reply and hands every reply
  // written for this vehicle by another participant (the bus owner) to the service's
  // peer_reply(), which keeps it while this instance does not own the bus. Call after start(),
  // on the same thread; throws dds::DdsError at start-up. The listener runs on Fast DDS's
  // threads and is detached by stop() as the command reader's is.
  void follow_peer_replies();
  // Stops reading commands (before the service is torn down): when it returns no callback
  // is running in, or will enter, the service. Idempotent.
  void stop();
  // Publishes one reply (thread-safe).
  void publish(const CommandReplyData& reply);
  // Received payloads that were not a pmu::v5::Command (counted and dropped, logged rate-limited).
  std::uint64_t malformed() const noexcept;
  // Commands for another vehicle, or written outside this vehicle's partition, since start.
  std::uint64_t not_ours() const noexcept;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace pmu::service
