#include "peers.hpp"

#include <linux/can.h>
#include <pthread.h>
#include <signal.h>
#include <sys/socket.h>

#include <atomic>
#include <cstdio>
#include <fastdds/dds/core/status/PublicationMatchedStatus.hpp>
#include <fastdds/dds/subscriber/DataReaderListener.hpp>
#include <fastdds/dds/subscriber/SampleInfo.hpp>
#include <thread>

#include "dds_probes.hpp"
#include "pacer.hpp"
#include "pmu/dds/dds_context.hpp"
#include "pmu/idl/command.h"
#include "pmu/idl/commandPubSubTypes.h"
#include "pmu/idl/telemetry.h"
#include "pmu/idl/telemetryPubSubTypes.h"
#include "pmu/idl/topics.hpp"

namespace pmu::bench {

using namespace eprosima::fastdds::dds;

StopFlag::StopFlag()
    : waiter_([this] {
        signals_.wait();
        stop_ = true;
      }) {}

StopFlag::~StopFlag() {
  // The run ended by itself: a SIGTERM to the waiter alone wakes it (it is pending for that
  // thread, which its signalfd reads).
  if (!stop_) pthread_kill(waiter_.native_handle(), SIGTERM);
  waiter_.join();
}

void StopFlag::wait() const {
  while (!stop_) std::this_thread::sleep_for(std::chrono::milliseconds(20));
}

int peer_writer(const PeerOptions& o) {
  // SIGTERM ends the run cleanly: a process killed with its participant alive leaves its
  // listener in Fast DDS's shared-memory ports, and every later participant opening those
  // ports then waits out a health check (333 ms each), which would skew the start-ups.
  StopFlag stop;
  pmu::dds::DdsContext dds(o.domain, o.qos_file, "bench-peer-writer", {}, o.transport);
  DataWriter& w = dds.writer(dds.topic(topics::kVoltages, TypeSupport(new pmu::v5::VoltagesPubSubType())),
                             qos_profiles::kTelemetry);
  for (int i = 0;; ++i) {
    if (stop) return 0;
    PublicationMatchedStatus s;
    w.get_publication_matched_status(s);
    if (s.current_count > 0) break;
    if (i > 2000) {
      std::fprintf(stderr, "peer-writer: no reader matched within 10 s\n");
      return 1;
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  }
  pmu::v5::Voltages v;
  v.bus("fd3");  // the same key (and so the same sample size) as the service's samples
  v.address(1);
  v.battery_a(kEmbeddedMarker);
  v.battery_b(22.2f);
  v.generator(48.0f);
  const auto count = static_cast<std::uint64_t>(o.rate * o.seconds);
  paced(o.rate, count, &stop.flag(), [&](std::uint64_t) {
    const auto t = static_cast<std::uint64_t>(steady_ns());
    v.avionics(static_cast<float>(t >> 48 & 0xFFFF));
    v.output_28v(static_cast<float>(t >> 32 & 0xFFFF));
    v.payload(static_cast<float>(t >> 16 & 0xFFFF));
    v.servo(static_cast<float>(t & 0xFFFF));
    w.write(&v);
  });
  if (!stop) std::this_thread::sleep_for(std::chrono::milliseconds(300));  // let the last samples arrive
  return 0;
}

namespace {

class Echo : public DataReaderListener {
 public:
  explicit Echo(DataWriter& replies) : replies_(replies) {}
  void on_data_available(DataReader* reader) override {
    pmu::v5::Command c;
    SampleInfo info;
    while (reader->take_next_sample(&c, &info) == ReturnCode_t::RETCODE_OK) {
      if (!info.valid_data) continue;
      pmu::v5::CommandReply r;
      r.request_id(c.request_id());
      r.bus(c.bus());
      r.address(c.address());
      r.kind(c.kind());
      r.result(pmu::v5::COMPLETED);
      r.has_value(true);
      r.value(15);
      replies_.write(&r);
    }
  }

 private:
  DataWriter& replies_;
};

}  // namespace

int peer_echo(const PeerOptions& o) {
  transport::StopSignals stop;
  pmu::dds::DdsContext dds(o.domain, o.qos_file, "bench-peer-echo", {}, o.transport);
  DataWriter& replies = dds.writer(dds.topic(topics::kCommandReply, TypeSupport(new pmu::v5::CommandReplyPubSubType())),
                                   qos_profiles::kCommand);
  Echo echo(replies);
  DataReader& requests = dds.reader(dds.topic(topics::kCommand, TypeSupport(new pmu::v5::CommandPubSubType())),
                                    qos_profiles::kCommand, &echo);
  stop.wait();
  requests.set_listener(nullptr);
  return 0;
}

int peer_pong() {
  struct can_frame f {};
  for (;;) {
    const ssize_t n = ::recv(3, &f, sizeof f, 0);
    if (n <= 0) return n == 0 ? 0 : 1;
    if (::send(3, &f, static_cast<std::size_t>(n), MSG_NOSIGNAL) != n) return 1;
  }
}

}  // namespace pmu::bench
