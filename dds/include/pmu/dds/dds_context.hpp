#pragma once
// DdsContext: one Fast DDS participant with the contract's topics and named QoS profiles
// (deploy/qos.xml), shared by pmu-service, pmuctl and the tests so every program creates
// entities the same way.
//
// Start-up only throws (DdsError: "cannot load QoS profiles from X", "cannot create
// participant on domain N"); afterwards calls return null or a ReturnCode like Fast DDS.
//
// Type objects: with `type_objects` the constructor registers the contract's type objects
// (dds_type_objects.hpp) before anything else, and the context's endpoints announce them;
// without (the default) no endpoint announces a type object or TypeInformation.
//
// Security: with SecurityFiles (security_files.hpp) the participant uses DDS-Security's
// builtin plugins (PKI-DH authentication, Access-Permissions, AES-GCM-GMAC crypto) with
// those files. Check them first (check_security_files): Fast DDS only says that the
// participant could not be created.
//
// Lifetime: the topics, writers and readers it returns belong to its participant and are
// valid until the context is destroyed; every object that keeps one (DdsPublisher,
// DdsCommandEndpoint) must be destroyed first. A listener given to
// writer() or reader() must outlive the context (Fast DDS may call it until the participant
// is deleted), or be removed from its endpoint first (set_listener(nullptr), as
// DdsCommandEndpoint::stop() does).
// Threads: the constructor, topic(), writer(), default_partition_writer() and reader() on one thread at a time (start-up;
// they share the topic map unlocked); remote_writers() from any thread (it locks).

#include <fastdds/dds/domain/DomainParticipant.hpp>
#include <fastdds/dds/publisher/DataWriter.hpp>
#include <fastdds/dds/publisher/Publisher.hpp>
#include <fastdds/dds/subscriber/DataReader.hpp>
#include <fastdds/dds/subscriber/Subscriber.hpp>
#include <fastdds/dds/topic/Topic.hpp>
#include <fastdds/dds/topic/TypeSupport.hpp>
#include <chrono>
#include <cstddef>
#include <cstdint>
#include <map>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include "pmu/dds_settings/network_settings.hpp"
#include "pmu/dds_settings/transport_choice.hpp"
#include "pmu/dds/contract_names.hpp"
#include "pmu/dds/dds_remote_writers.hpp"
#include "pmu/security/security_files.hpp"

namespace pmu::dds {

class DdsError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// Fast DDS refused a writer or reader, and the identity's permissions say why: they do not
// grant `partition()` ("" is the default partition) for that topic. A program that maps
// partitions to vehicles (pmuctl) can then say which vehicle the identity may not use.
class PartitionNotGranted : public DdsError {
 public:
  PartitionNotGranted(const std::string& what, std::string partition)
      : DdsError(what), partition_(std::move(partition)) {}
  const std::string& partition() const noexcept { return partition_; }

 private:
  std::string partition_;
};

// The installed qos.xml: $PMU_QOS_FILE, else qos.xml in the configuration directory
// (PMU_SYSCONFDIR, /etc/pmu-dds), else the read-only copy the client tools ship (PMU_DATADIR,
// /usr/share/pmu-dds). Empty when none exists. Never the source tree: runs from a
// build directory set PMU_QOS_FILE (scripts/run.sh and the tests do).
std::string default_qos_file();

// The first of the Fast DDS statistics topics `topics` that the permissions of `security`
// do not let this identity publish in the default partition, where Fast DDS creates their
// writers (and a refused one is only logged), or nullopt. DdsContext refuses to start with
// one; pmu-service's start-up check (startup_check.hpp) says so first, at the config line.
std::optional<std::string> statistics_topic_not_granted(const SecurityFiles& security,
                                                        const std::vector<std::string>& topics);


// The participant name of every pmu-service: a client that sees a participant of this name
// knows a service's endpoints are on their way (interface.md section 7).
inline constexpr const char* kServiceParticipantName = "pmu-service";

// The DDS partitions of the participant's one publisher and one subscriber (empty: the
// default partition). vehicle.hpp says which a service and a client use.
struct Partitions {
  std::vector<std::string> publisher;
  std::vector<std::string> subscriber;
};

class DdsContext {
 public:
  // `security` empty: no DDS-Security (as before). Relative paths are made absolute.
  // `network`: discovery and interface allowlist (network_settings.hpp); default multicast, all.
  // `statistics`: the Fast DDS statistics topics to write (statistics_settings.hpp), checked
  // names; with DDS-Security the permissions must allow publishing each, or DdsError says so.
  // `type_objects`: announce the self-contained types' type objects (see above).
  // `contract`: the major version whose type names the context's topics use
  // (contract_names.hpp): the previous one makes a participant that serves that contract's
  // consumers: this build's types under its names, those it changed converted
  // (previous_contract.hpp; tests/contract checks that no other type changed). Announced as the
  // participant property kContractProperty. An older contract never has type objects.
  DdsContext(int domain, const std::string& qos_file, const std::string& participant_name,
             const SecurityFiles& security = {}, Transport transport = Transport::Default,
             const ResolvedNetwork& network = {}, const Partitions& partitions = {},
             const std::vector<std::string>& statistics = {}, bool type_objects = false,
             int contract = contract_major());
  ~DdsContext();
  DdsContext(const DdsContext&) = delete;
  DdsContext& operator=(const DdsContext&) = delete;

  eprosima::fastdds::dds::DomainParticipant& participant() { return *participant_; }
  int domain() const noexcept { return domain_; }
  bool secure() const noexcept { return secure_; }
  // Every remote writer discovery reported since the participant was created, with its
  // partitions (dds_remote_writers.hpp).
  const RemoteWriters& remote_writers() const noexcept { return remote_writers_; }

  // Registers the type (once) and creates the topic (once). `type` is e.g.
  // new pmu::v5::VoltagesPubSubType(); it is registered under contract()'s name for it. Its endpoints announce its type object when the context
  // was made with type_objects and the type is self-contained, never its TypeInformation
  // (dds_type_objects.hpp says why). Throws
  // DdsError at start-up when it fails.
  eprosima::fastdds::dds::Topic& topic(const std::string& name, eprosima::fastdds::dds::TypeSupport type);

  // A writer/reader with the named profile of qos.xml. Throws DdsError when it fails, and
  // when the profile holds less than the declared capacity (capacity.hpp, dds_capacity.hpp).
  // With DDS-Security the message says what the permissions do not allow (the topic, or
  // which partition), and PartitionNotGranted is thrown when it is a partition.
  eprosima::fastdds::dds::DataWriter& writer(eprosima::fastdds::dds::Topic& topic, const std::string& profile,
                                             eprosima::fastdds::dds::DataWriterListener* listener = nullptr);
  eprosima::fastdds::dds::DataReader& reader(eprosima::fastdds::dds::Topic& topic, const std::string& profile,
                                             eprosima::fastdds::dds::DataReaderListener* listener = nullptr);

  // From now on, reliable writers heartbeat at most this often (their profile's period when
  // that is longer): the link's floor (network.link.heartbeat_floor, set by the constructor
  // from `link:` or pmuctl's --link; config.hpp says why). Call before the
  // writers are made (a writer's period cannot change once it exists); the writers' thread.
  void heartbeat_at_least(std::chrono::milliseconds period) noexcept { heartbeat_floor_ = period; }

  // A writer in the default partition with `qos` as given, not from qos.xml: for ROS 2's
  // topics (ros2_publisher.hpp), whose partition and QoS are what ROS 2 subscribers expect
  // rather than a tuning of this service. Throws DdsError like writer().
  eprosima::fastdds::dds::DataWriter& default_partition_writer(eprosima::fastdds::dds::Topic& topic,
                                                               const eprosima::fastdds::dds::DataWriterQos& qos);

  // A reader in the default partition with `qos` as given, not from qos.xml: for ROS 2's
  // topics read as a ROS 2 subscriber reads them (pmuctl record and serve). Throws DdsError
  // like reader(); `listener` as for reader().
  eprosima::fastdds::dds::DataReader& default_partition_reader(eprosima::fastdds::dds::Topic& topic,
                                                               const eprosima::fastdds::dds::DataReaderQos& qos,
                                                               eprosima::fastdds::dds::DataReaderListener* listener);

  // The writers and readers made by writer() and reader() so far. A long-lived context that
  // serves one job after another (`pmuctl agent`) deletes each job's endpoints when it ends
  // (delete_endpoints_since), so its participant does not grow with every job. Deleting
  // writers moves the publisher to a partition nobody uses first (the Fast DDS 2.9 hang the
  // destructor avoids the same way): call set_partitions before the next job's endpoints.
  // Same thread rule as writer() and reader(); every reference to a deleted endpoint is then
  // dangling.
  // Moves the publisher and subscriber to other partitions (Fast DDS lets a partition change
  // while the participant lives). For a context that serves one job after another, each job
  // in its own vehicle's partitions, set while it has no endpoints. False when Fast DDS
  // refuses. Same thread rule as writer() and reader().
  bool set_partitions(const Partitions& partitions);

  struct EndpointMark {
    std::size_t writers = 0;
    std::size_t readers = 0;
  };
  EndpointMark endpoint_mark() const noexcept { return {writers_.size(), readers_.size()}; }
  void delete_endpoints_since(EndpointMark mark);

  // From now on a job's writers and readers (those without a listener) are parked rather
  // than deleted by delete_endpoints_since, and a later job's writer() or reader() of the
  // same topic and profile gets a parked one back, moved to that job's partitions; a reader
  // comes back without the samples it held. Each such endpoint has a publisher or subscriber
  // of its own, which parking moves to a partition nobody uses, so the remote endpoints
  // unmatch it on an update of its discovery data, unless its profile is one of
  // `idle_matched`. Why not delete: a Fast DDS Discovery
  // Server (2.9 to 3.x), processing one endpoint's disposal, drops from its history every
  // other announcement of the same participant that its clients have not all received,
  // disposals included. A participant that deletes two endpoints at once then leaves one
  // matched at the other clients for as long as it lives, and a reliable writer heartbeats
  // such a reader every period, for ever: a long-lived participant of a ground station over
  // a radio link filled the link with them. The parked endpoints are bounded by the most a
  // job uses at once, per topic and profile. Same thread rule as writer() and reader().
  // `idle_matched`: profiles whose endpoints stay matched in their partitions while idle
  // (nothing flows to them unasked, so a later job in the same partitions finds them matched
  // at no cost to the link); the others are parked. A job in other partitions gets a new one
  // of these rather than one moved from the partitions it serves, up to kMostIdleMatched of
  // a topic and profile (a ground station's fleet); beyond, the least recently used moves.
  static constexpr std::size_t kMostIdleMatched = 16;
  void reuse_endpoints(std::vector<std::string> idle_matched) {
    reuse_ = true;
    idle_matched_ = std::move(idle_matched);
  }

 private:
  // An endpoint of `publisher` or `subscriber` with the named profile, its capacity checked;
  // throws like writer() and reader().
  eprosima::fastdds::dds::DataWriter* make_writer(eprosima::fastdds::dds::Publisher& publisher,
                                                  eprosima::fastdds::dds::Topic& topic, const std::string& profile,
                                                  eprosima::fastdds::dds::DataWriterListener* listener);
  eprosima::fastdds::dds::DataReader* make_reader(eprosima::fastdds::dds::Subscriber& subscriber,
                                                  eprosima::fastdds::dds::Topic& topic, const std::string& profile,
                                                  eprosima::fastdds::dds::DataReaderListener* listener);
  // Throws the DdsError for an endpoint Fast DDS refused ("cannot create a writer for ...").
  [[noreturn]] void refused(const std::string& topic, const std::string& profile, bool publish) const;
  // Throws the DdsError for an endpoint whose profile cannot hold what its topic needs
  // (`shortfall`, from capacity_shortfall), naming the profile in the QoS file.
  [[noreturn]] void too_small(const std::string& topic, const std::string& profile, bool publish,
                              const std::string& shortfall) const;

  int domain_;
  int contract_;
  bool type_objects_;
  std::string qos_file_;
  bool secure_ = false;
  SecurityFiles security_;
  Partitions partitions_;
  RemoteWriters remote_writers_;  // the participant's listener: outlives it
  eprosima::fastdds::dds::DomainParticipant* participant_ = nullptr;
  eprosima::fastdds::dds::Publisher* publisher_ = nullptr;
  eprosima::fastdds::dds::Publisher* default_publisher_ = nullptr;    // made by the first default_partition_writer()
  eprosima::fastdds::dds::Subscriber* default_subscriber_ = nullptr;  // made by the first default_partition_reader()
  eprosima::fastdds::dds::Subscriber* subscriber_ = nullptr;
  std::map<std::string, eprosima::fastdds::dds::Topic*> topics_;
  std::vector<eprosima::fastdds::dds::DataWriter*> writers_;  // made by writer(), in order
  std::vector<eprosima::fastdds::dds::DataReader*> readers_;  // made by reader(), in order

  // An endpoint kept for reuse (reuse_endpoints), with its own publisher or subscriber.
  struct Kept {
    std::string topic;
    std::string profile;
    std::vector<std::string> partitions;                     // its publisher's or subscriber's now
    eprosima::fastdds::dds::Publisher* publisher = nullptr;  // a writer's
    eprosima::fastdds::dds::DataWriter* writer = nullptr;
    eprosima::fastdds::dds::Subscriber* subscriber = nullptr;  // a reader's
    eprosima::fastdds::dds::DataReader* reader = nullptr;
    bool in_use = false;
    std::uint64_t taken_up = 0;  // when last taken up, in take_ups_
  };
  std::uint64_t take_ups_ = 0;
  bool reuse_ = false;
  std::vector<std::string> idle_matched_;
  std::chrono::milliseconds heartbeat_floor_{0};
  std::vector<Kept> kept_;
  eprosima::fastdds::dds::DataWriter* kept_writer(eprosima::fastdds::dds::Topic& topic, const std::string& profile);
  eprosima::fastdds::dds::DataReader* kept_reader(eprosima::fastdds::dds::Topic& topic, const std::string& profile);
  // An idle kept writer (`writer`) or reader of this topic and profile, in `partitions` (one
  // already there first, else the least recently used moved there, but not an idle-matched
  // one while fewer than kMostIdleMatched exist), marked in use; a reader emptied. Null
  // when there is none to take: the caller makes one.
  Kept* take_up(const std::string& topic, const std::string& profile, bool writer,
                const std::vector<std::string>& partitions);
  // Moves a kept endpoint's publisher or subscriber; false when Fast DDS refuses.
  bool move(Kept& k, const std::vector<std::string>& partitions);
  // Parks `endpoint` when it is a kept one in use (true); false when it was not kept.
  bool park(const eprosima::fastdds::dds::DomainEntity* endpoint);
};

}  // namespace pmu::dds
