#include "dds_probes.hpp"

#include <cmath>
#include <fastdds/dds/core/status/PublicationMatchedStatus.hpp>
#include <fastdds/dds/core/status/SubscriptionMatchedStatus.hpp>
#include <fastdds/dds/subscriber/SampleInfo.hpp>
#include <fastdds/dds/subscriber/Subscriber.hpp>
#include <fastdds/dds/subscriber/qos/DataReaderQos.hpp>
#include <stdexcept>
#include <thread>

#include "pacer.hpp"

#include "pmu/idl/command.h"
#include "pmu/idl/commandPubSubTypes.h"
#include "pmu/idl/telemetry.h"
#include "pmu/idl/telemetryPubSubTypes.h"
#include "pmu/idl/topics.hpp"

namespace pmu::bench {

using namespace eprosima::fastdds::dds;

namespace {

std::int64_t embedded_time(const pmu::v5::Voltages& v) {
  const auto part = [](float f) { return static_cast<std::uint64_t>(f); };
  return static_cast<std::int64_t>(part(v.avionics()) << 48 | part(v.output_28v()) << 32 | part(v.payload()) << 16 |
                                   part(v.servo()));
}

const char* result_name(int r) {
  static const char* const names[] = {"COMPLETED", "REJECTED", "DENIED",     "UNSUPPORTED",
                                      "TIMEOUT",   "FAILED",   "IN_PROGRESS"};
  return r >= 0 && r < 7 ? names[r] : "?";
}

}  // namespace

VoltagesProbe::VoltagesProbe(pmu::dds::DdsContext& dds, WriteTimes* times) : dds_(dds), times_(times) {
  latencies_.reserve(1 << 20);
  // The telemetry profile, but a history deep enough that a burst of samples waiting for
  // this listener is not overwritten: a loss counted here is then the sender's, not the
  // probe's (service and reference alike).
  auto& topic = dds.topic(topics::kVoltages, TypeSupport(new pmu::v5::VoltagesPubSubType()));
  subscriber_ = dds.participant().create_subscriber(SUBSCRIBER_QOS_DEFAULT);
  DataReaderQos qos;
  if (!subscriber_ ||
      subscriber_->get_datareader_qos_from_profile(qos_profiles::kTelemetry, qos) != ReturnCode_t::RETCODE_OK)
    throw std::runtime_error("no telemetry reader profile in the QoS file");
  qos.history().depth = 4096;
  qos.resource_limits().max_instances = 4;
  qos.resource_limits().max_samples = 4 * 4096;
  qos.resource_limits().max_samples_per_instance = 4096;
  reader_ = subscriber_->create_datareader(&topic, qos, this);
  if (!reader_) throw std::runtime_error("cannot create the pmu/voltages probe reader");
}

VoltagesProbe::~VoltagesProbe() {
  reader_->set_listener(nullptr);
  subscriber_->delete_datareader(reader_);
  dds_.participant().delete_subscriber(subscriber_);
}

void VoltagesProbe::on_sample_lost(DataReader*, const SampleLostStatus& status) {
  if (status.total_count_change > 0) lost_ += static_cast<std::uint64_t>(status.total_count_change);
}

void VoltagesProbe::on_data_available(DataReader* reader) {
  pmu::v5::Voltages v;
  SampleInfo info;
  while (reader->take_next_sample(&v, &info) == ReturnCode_t::RETCODE_OK) {
    const std::int64_t now = steady_ns();
    if (!info.valid_data) continue;
    std::int64_t written = 0;
    if (times_) {
      if (std::lround(v.avionics() * 10.0f) != kMarkerRaw) continue;  // the model's own stream
      const auto seq = static_cast<std::uint16_t>(std::lround(v.battery_a() * 10.0f) * kSeqBase +
                                                  std::lround(v.battery_b() * 10.0f));
      written = times_->take(seq);
    } else if (v.battery_a() == kEmbeddedMarker) {
      written = embedded_time(v);
    }
    if (written == 0) continue;
    ++received_;
    std::int64_t none = 0;
    first_.compare_exchange_strong(none, now);
    last_ = now;
    std::lock_guard lock(mutex_);
    latencies_.push_back(now - written);
  }
}

std::vector<std::int64_t> VoltagesProbe::take_latencies() {
  std::lock_guard lock(mutex_);
  std::vector<std::int64_t> out;
  out.swap(latencies_);
  latencies_.reserve(1 << 20);
  return out;
}

bool VoltagesProbe::wait_matched(std::chrono::milliseconds timeout) {
  const auto until = std::chrono::steady_clock::now() + timeout;
  for (;;) {
    SubscriptionMatchedStatus s;
    reader_->get_subscription_matched_status(s);
    if (s.current_count > 0) return true;
    if (std::chrono::steady_clock::now() >= until) return false;
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  }
}

CommandClient::CommandClient(pmu::dds::DdsContext& dds) : dds_(dds) {
  replies_ = &dds.reader(dds.topic(topics::kCommandReply, TypeSupport(new pmu::v5::CommandReplyPubSubType())),
                         qos_profiles::kCommand, this);
  writer_ =
      &dds.writer(dds.topic(topics::kCommand, TypeSupport(new pmu::v5::CommandPubSubType())), qos_profiles::kCommand);
}

CommandClient::~CommandClient() { replies_->set_listener(nullptr); }

void CommandClient::on_data_available(DataReader* reader) {
  pmu::v5::CommandReply r;
  SampleInfo info;
  while (reader->take_next_sample(&r, &info) == ReturnCode_t::RETCODE_OK) {
    if (!info.valid_data || r.result() == pmu::v5::IN_PROGRESS) continue;
    std::lock_guard lock(mutex_);
    if (r.request_id().to_string() != waiting_for_) continue;
    answered_ = true;
    result_ = static_cast<int>(r.result());
    cv_.notify_one();
  }
}

bool CommandClient::wait_matched(std::chrono::milliseconds timeout) {
  const auto until = std::chrono::steady_clock::now() + timeout;
  for (;;) {
    PublicationMatchedStatus pub;
    SubscriptionMatchedStatus sub;
    writer_->get_publication_matched_status(pub);
    replies_->get_subscription_matched_status(sub);
    if (pub.current_count > 0 && sub.current_count > 0) return true;
    if (std::chrono::steady_clock::now() >= until) return false;
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  }
}

CommandClient::Result CommandClient::run(int count, const std::string& bus, std::uint16_t address,
                                         std::chrono::milliseconds each_timeout) {
  Result out;
  static int session = 0;
  ++session;
  for (int i = 0; i < count; ++i) {
    pmu::v5::Command c;
    const std::string id = "bench-" + std::to_string(session) + "-" + std::to_string(i);
    c.request_id(id);
    c.bus(bus);
    c.address(address);
    c.kind(pmu::v5::GET);
    c.parameter("outputs");
    {
      std::lock_guard lock(mutex_);
      waiting_for_ = id;
      answered_ = false;
    }
    const std::int64_t sent = steady_ns();
    writer_->write(&c);
    std::unique_lock lock(mutex_);
    if (!cv_.wait_for(lock, each_timeout, [this] { return answered_; })) {
      ++out.timeouts;
      continue;
    }
    const std::int64_t rtt = steady_ns() - sent;
    if (result_ == static_cast<int>(pmu::v5::COMPLETED))
      out.rtt_ns.push_back(rtt);
    else
      ++out.results[result_name(result_)];
  }
  return out;
}

}  // namespace pmu::bench
