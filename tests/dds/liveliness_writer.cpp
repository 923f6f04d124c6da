// The writer of the liveliness test (liveliness_test.cpp): one participant, one writer of the
// probe topic with the given liveliness kind and liveliness_probe.hpp's lease, writing a
// sample every kWritePeriodMs until SIGTERM (then it leaves cleanly) or SIGKILL (the test's
// way of a host that dies without a word).
//
//   liveliness_writer DOMAIN AUTOMATIC|MANUAL_BY_PARTICIPANT|MANUAL_BY_TOPIC
#include <fastdds/dds/domain/DomainParticipant.hpp>
#include <fastdds/dds/domain/DomainParticipantFactory.hpp>
#include <fastdds/dds/publisher/DataWriter.hpp>
#include <fastdds/dds/publisher/Publisher.hpp>
#include <fastdds/dds/topic/Topic.hpp>
#include <fastdds/dds/topic/TypeSupport.hpp>
#include <signal.h>

#include <chrono>
#include <cstdint>
#include <cstdio>
#include <string>
#include <thread>

#include "liveliness_probe.hpp"

namespace {

volatile sig_atomic_t liveliness_writer_stop = 0;

void on_liveliness_writer_term(int) { liveliness_writer_stop = 1; }

}  // namespace

int main(int argc, char** argv) {
  using namespace eprosima::fastdds::dds;
  namespace probe = pmu::test::liveliness_probe;
  const auto kind = argc == 3 ? probe::kind_named(argv[2]) : std::nullopt;
  if (!kind) {
    std::fprintf(stderr, "usage: liveliness_writer DOMAIN AUTOMATIC|MANUAL_BY_PARTICIPANT|MANUAL_BY_TOPIC\n");
    return 2;
  }
  const auto domain = static_cast<DomainId_t>(std::stoul(argv[1]));
  struct sigaction sa {};
  sa.sa_handler = on_liveliness_writer_term;
  sigaction(SIGTERM, &sa, nullptr);

  auto* factory = DomainParticipantFactory::get_instance();
  DomainParticipant* participant =
      factory->create_participant(domain, probe::participant_qos(std::string("liveliness-writer-") + argv[2]));
  if (participant == nullptr) {
    std::fprintf(stderr, "liveliness_writer: no participant on domain %u\n", domain);
    return 1;
  }
  TypeSupport type(new probe::CounterType());
  type.register_type(participant);
  Topic* topic = participant->create_topic(probe::kTopic, probe::kTypeName, TOPIC_QOS_DEFAULT);
  Publisher* publisher = participant->create_publisher(PUBLISHER_QOS_DEFAULT);
  DataWriterQos wq = DATAWRITER_QOS_DEFAULT;
  wq.reliability().kind = RELIABLE_RELIABILITY_QOS;
  wq.history().kind = KEEP_LAST_HISTORY_QOS;
  wq.history().depth = 1;
  wq.liveliness().kind = *kind;
  wq.liveliness().lease_duration = probe::milliseconds(probe::kLeaseMs);
  wq.liveliness().announcement_period = probe::milliseconds(probe::kAnnouncementMs);
  DataWriter* writer = topic && publisher ? publisher->create_datawriter(topic, wq) : nullptr;
  if (writer == nullptr) {
    std::fprintf(stderr, "liveliness_writer: no writer\n");
    return 1;
  }
  std::uint32_t count = 0;
  while (!liveliness_writer_stop) {
    ++count;
    writer->write(&count);
    std::this_thread::sleep_for(std::chrono::milliseconds(probe::kWritePeriodMs));
  }
  participant->delete_contained_entities();
  factory->delete_participant(participant);
  return 0;
}
