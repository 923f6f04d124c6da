#include "pmu/dds/dds_context.hpp"

#include <fastdds/dds/domain/DomainParticipantFactory.hpp>

#include <fastdds/dds/subscriber/SampleInfo.hpp>

#include <unistd.h>

#include <algorithm>
#include <cstdlib>
#include <memory>
#include <mutex>
#include <spdlog/spdlog.h>

#include "pmu/dds/dds_capacity.hpp"
#include "pmu/dds/dds_participant.hpp"
#include "pmu/dds/dds_qos_file.hpp"
#include "pmu/dds/dds_type_objects.hpp"
#include "pmu/dds/previous_contract.hpp"
#include "pmu/dds/security_match_guard.hpp"
#include "pmu/sysconf_dir.hpp"

namespace pmu::dds {
namespace {

using namespace eprosima::fastdds::dds;

// Whether the file is there to be read; opening it to see would block on a FIFO. A file that
// is there but no regular one is refused with its reason when the profiles are loaded.
bool readable(const std::string& path) { return ::access(path.c_str(), R_OK) == 0; }

// Fast DDS 2.9.1 (Debian bookworm's) can hang forever deleting a reliable writer whose readers
// have not acknowledged everything. Its destructor (RTPSWriter::deinit) returns the history's
// samples to their pool one at a time, dropping the writer's lock between them, while the history
// still lists them with their sequence numbers reset to 0, and the periodic heartbeat stays armed
// until after that. A heartbeat that fires in between walks the history for holes
// (StatefulWriter::add_gaps_for_holes_in_history_): from the first freed sample's 0 + 1 it counts
// up to the next one's number, 0 again, i.e. through the whole 64-bit sequence space, holding
// the lock the destructor waits for. The four-writer burst of command_boundary_test.cpp hung so
// in a client's teardown. Fixed upstream in 2.13.0 (eProsima/Fast-DDS#4076; backported to 2.6.10,
// 2.10.3, 2.11.3 and 2.12.2, never to 2.9).
// The heartbeat needs a matched reader: with none it sends nothing and its timer is cancelled.
// Moving the publisher to a partition nobody subscribes to unmatches every reader of its writers
// at once (Fast DDS re-pairs a writer synchronously when its publisher's QoS changes), so the
// deletion that follows has nobody to send a heartbeat to. Readers lose nothing they would have
// kept: a deleted writer repairs nothing either. The partition starts with '#', which no vehicle
// name can (vehicle.hpp), so even the every-vehicle readers' pattern does not match it.
constexpr const char* kClosingPartition = "#pmu-dds-closing";

// A publisher or subscriber moved to other partitions (Fast DDS lets them change while the
// participant lives). False when Fast DDS refuses.
template <class Entity>
bool move_to(Entity& entity, const std::vector<std::string>& partitions) {
  auto qos = entity.get_qos();
  qos.partition().clear();
  for (const auto& p : partitions) qos.partition().push_back(p.c_str());
  return entity.set_qos(qos) == ReturnCode_t::RETCODE_OK;
}

void unmatch_writers_before_deleting_them(Publisher& publisher) {
  (void)move_to(publisher, {kClosingPartition});  // if refused, the deletion runs as before: nothing else to do
}

// Takes every sample a reader holds, whatever its type (through the reader's type support).
void drain(DataReader& reader) {
  TypeSupport type = reader.type();
  void* sample = type->createData();
  SampleInfo info;
  while (reader.take_next_sample(sample, &info) == ReturnCode_t::RETCODE_OK) {
  }
  type->deleteData(sample);
}

// `"uav1"`, or `the default partition` for "", in messages.
std::string partition_text(const std::string& p) {
  return p.empty() ? std::string("the default partition") : "partition \"" + p + "\"";
}

// `"", "uav1"`: the granted patterns, as the permissions spell them.
std::string patterns_text(const std::vector<std::string>& patterns) {
  std::string s;
  for (const auto& p : patterns) s += (s.empty() ? "\"" : ", \"") + p + "\"";
  return s;
}

}  // namespace

std::optional<std::string> statistics_topic_not_granted(const SecurityFiles& security,
                                                        const std::vector<std::string>& topics) {
  for (const auto& topic : topics)
    if (const auto grant = topic_grant(security, topic, true);
        !grant || !grant->allowed || partition_not_granted({}, grant->partitions))
      return topic;
  return std::nullopt;
}

std::string default_qos_file() {
  if (const char* env = std::getenv("PMU_QOS_FILE"); env && *env) return env;
  // Only installed places: a binary that also looked in its build tree would carry that
  // path into the package. Runs from a build directory set PMU_QOS_FILE.
  if (const char* installed = PMU_SYSCONFDIR "/qos.xml"; readable(installed)) return installed;
  // The client tools are packaged without the daemon's /etc/pmu-dds (pmu-dds-tools): their
  // copy of the profiles is read-only data. The site's edited /etc file still wins.
  if (const char* shipped = PMU_DATADIR "/qos.xml"; readable(shipped)) return shipped;
  return {};
}

DdsContext::DdsContext(int domain, const std::string& qos_file, const std::string& participant_name,
                       const SecurityFiles& security, Transport transport, const ResolvedNetwork& network,
                       const Partitions& partitions, const std::vector<std::string>& statistics, bool type_objects,
                       int contract)
    : domain_(domain),
      contract_(contract),
      type_objects_(type_objects && contract == contract_major()),
      secure_(!security.empty()),
      security_(security),
      partitions_(partitions) {
  const std::string file = qos_file.empty() ? default_qos_file() : qos_file;
  qos_file_ = file;
  if (file.empty())
    throw DdsError("no QoS profile file: neither " PMU_SYSCONFDIR "/qos.xml nor " PMU_DATADIR
                   "/qos.xml exists; install deploy/qos.xml, set PMU_QOS_FILE or set qos_file");
  load_qos_profiles(file);
  // Before any endpoint exists: Fast DDS copies a type's object into the endpoint's discovery
  // data when the endpoint is created, from what is registered then.
  if (type_objects_) register_type_objects();
  // Fast DDS creates statistics writers in the default partition when the participant is
  // enabled; a writer the permissions refuse is only logged, and the topic stays silent.
  if (secure_)
    if (const auto topic = statistics_topic_not_granted(security_, statistics))
      throw DdsError("dds_statistics: this identity's permissions do not allow publishing " + *topic +
                     " in the default partition (DDS-Security; docs/interface.md section 6 says what to grant)");
  // Without the guard a secured participant may never authenticate a peer it found at the
  // same time as another (security_match_guard.hpp).
  if (secure_ && !security_match_guard_active())
    spdlog::warn(
        "DDS-Security without the guard against Fast DDS 2.9.1's matching race: a peer found at the same "
        "moment as another may stay unauthenticated until one of them restarts");
  // Transports, discovery, interfaces, security and statistics: dds_participant.hpp says what each sets.
  DomainParticipantQos pqos;
  try {
    pqos = participant_qos(participant_name, transport, network, security, statistics);
  } catch (const NetworkError& e) {
    throw DdsError(e.what());
  }
  // The link's floor (link_profile.hpp): every reliable writer of this participant, the
  // service's and pmuctl's alike.
  heartbeat_floor_ = network.link.heartbeat_floor.value;
  // Sent in discovery, so a client tells which contract a participant serves before its
  // endpoints are announced (seconds later over a slow link).
  pqos.properties().properties().emplace_back(kContractProperty, std::to_string(contract), true);
  // The listener from the start: discovery is not replayed to one set later.
  participant_ = DomainParticipantFactory::get_instance()->create_participant(static_cast<DomainId_t>(domain), pqos,
                                                                              &remote_writers_, StatusMask::none());
  if (!participant_)
    throw DdsError("cannot create a DDS participant on domain " + std::to_string(domain) +
                   (secure_ ? " with DDS-Security (see the Fast DDS SECURITY error above)" : "") +
                   (network.mode == DiscoveryMode::Multicast && network.interface_addresses.empty()
                        ? ""
                        : " (" + network.summary + ")"));
  PublisherQos pub_qos = PUBLISHER_QOS_DEFAULT;
  for (const auto& p : partitions.publisher) pub_qos.partition().push_back(p.c_str());
  SubscriberQos sub_qos = SUBSCRIBER_QOS_DEFAULT;
  for (const auto& p : partitions.subscriber) sub_qos.partition().push_back(p.c_str());
  publisher_ = participant_->create_publisher(pub_qos);
  subscriber_ = participant_->create_subscriber(sub_qos);
  if (!publisher_ || !subscriber_) {
    DomainParticipantFactory::get_instance()->delete_participant(participant_);
    throw DdsError(
        "cannot create a DDS publisher/subscriber on domain " + std::to_string(domain) +
        (secure_ ? " (DDS-Security: this identity's permissions may not allow its vehicle's partition)" : ""));
  }
}

DdsContext::~DdsContext() {
  if (!participant_) return;
  for (const auto& k : kept_)
    if (k.publisher) unmatch_writers_before_deleting_them(*k.publisher);
  unmatch_writers_before_deleting_them(*publisher_);
  if (default_publisher_) unmatch_writers_before_deleting_them(*default_publisher_);
  participant_->delete_contained_entities();
  DomainParticipantFactory::get_instance()->delete_participant(participant_);
}

Topic& DdsContext::topic(const std::string& name, TypeSupport type) {
  if (auto it = topics_.find(name); it != topics_.end()) return *it->second;
  if (contract_ != contract_major()) {
    // The previous contract: a type it laid out or filled otherwise is converted, every other
    // type is this contract's under the previous contract's name (previous_contract.hpp).
    auto converting = contract_ == contract_major() - 1 ? previous_contract_type(type) : TypeSupport();
    if (converting)
      type = converting;
    else
      type->setName(type_name_in_contract(type.get_type_name(), contract_).c_str());
  }
  const std::string type_name = type.get_type_name();
  announce_type_object(type, type_objects_);  // never TypeInformation; the type object when asked and self-contained
  if (type.register_type(participant_) != ReturnCode_t::RETCODE_OK)
    throw DdsError("cannot register DDS type " + type_name);
  Topic* t = participant_->create_topic(name, type_name, TOPIC_QOS_DEFAULT);
  if (!t) throw DdsError("cannot create DDS topic " + name);
  topics_[name] = t;
  return *t;
}

DataWriter& DdsContext::writer(Topic& topic, const std::string& profile, DataWriterListener* listener) {
  DataWriter* w =
      reuse_ && !listener ? kept_writer(topic, profile) : make_writer(*publisher_, topic, profile, listener);
  writers_.push_back(w);
  return *w;
}

DataWriter* DdsContext::make_writer(Publisher& publisher, Topic& topic, const std::string& profile,
                                    DataWriterListener* listener) {
  DataWriter* w = nullptr;
  DataWriterQos qos;
  if (heartbeat_floor_.count() > 0 &&
      publisher.get_datawriter_qos_from_profile(profile, qos) == ReturnCode_t::RETCODE_OK &&
      qos.reliability().kind == eprosima::fastdds::dds::RELIABLE_RELIABILITY_QOS) {
    const auto ns = std::chrono::duration_cast<std::chrono::nanoseconds>(heartbeat_floor_).count();
    const eprosima::fastrtps::Duration_t floor(static_cast<std::int32_t>(ns / 1000000000),
                                               static_cast<std::uint32_t>(ns % 1000000000));
    auto& period = qos.reliable_writer_qos().times.heartbeatPeriod;
    if (period < floor) period = floor;
    w = publisher.create_datawriter(&topic, qos, listener);
  } else {
    w = publisher.create_datawriter_with_profile(&topic, profile, listener);
  }
  if (!w) refused(topic.get_name(), profile, true);
  const DataWriterQos q = w->get_qos();
  if (const auto s = capacity_shortfall(profile, EndpointKind::Writer, q.resource_limits(), q.history()); !s.empty()) {
    publisher.delete_datawriter(w);
    too_small(topic.get_name(), profile, true, s);
  }
  return w;
}

DataReader& DdsContext::reader(Topic& topic, const std::string& profile, DataReaderListener* listener) {
  DataReader* r =
      reuse_ && !listener ? kept_reader(topic, profile) : make_reader(*subscriber_, topic, profile, listener);
  readers_.push_back(r);
  return *r;
}

DataReader* DdsContext::make_reader(Subscriber& subscriber, Topic& topic, const std::string& profile,
                                    DataReaderListener* listener) {
  DataReader* r = subscriber.create_datareader_with_profile(&topic, profile, listener);
  if (!r) refused(topic.get_name(), profile, false);
  const DataReaderQos q = r->get_qos();
  if (const auto s = capacity_shortfall(profile, EndpointKind::Reader, q.resource_limits(), q.history()); !s.empty()) {
    subscriber.delete_datareader(r);
    too_small(topic.get_name(), profile, false, s);
  }
  return r;
}

bool DdsContext::set_partitions(const Partitions& partitions) {
  if (!move_to(*publisher_, partitions.publisher) || !move_to(*subscriber_, partitions.subscriber)) return false;
  partitions_ = partitions;
  return true;
}

bool DdsContext::move(Kept& k, const std::vector<std::string>& partitions) {
  if (!(k.publisher ? move_to(*k.publisher, partitions) : move_to(*k.subscriber, partitions))) return false;
  k.partitions = partitions;
  return true;
}

DdsContext::Kept* DdsContext::take_up(const std::string& topic, const std::string& profile, bool writer,
                                      const std::vector<std::string>& partitions) {
  std::size_t alike = 0;
  Kept* here = nullptr;    // idle, in these partitions: taking it up costs the link nothing
  Kept* oldest = nullptr;  // idle elsewhere, the least recently taken up
  for (auto& k : kept_) {
    if ((k.writer != nullptr) != writer || k.topic != topic || k.profile != profile) continue;
    ++alike;
    if (k.in_use) continue;
    if (k.partitions == partitions) {
      if (!here) here = &k;
    } else if (!oldest || k.taken_up < oldest->taken_up) {
      oldest = &k;
    }
  }
  // One left matched in another vehicle's partitions serves that vehicle's next command
  // there; moved, it would be announced again across the link twice.
  const bool idle_matched = std::find(idle_matched_.begin(), idle_matched_.end(), profile) != idle_matched_.end();
  if (!here && oldest && idle_matched && alike < kMostIdleMatched) oldest = nullptr;
  Kept* k = here ? here : oldest;
  if (!k) return nullptr;
  // What a reader holds is an earlier job's (one left matched may also hold replies to
  // other clients since).
  if (k->reader) drain(*k->reader);
  if (k != here && !move(*k, partitions)) return nullptr;
  k->in_use = true;
  k->taken_up = ++take_ups_;
  return k;
}

DataWriter* DdsContext::kept_writer(Topic& topic, const std::string& profile) {
  if (Kept* k = take_up(topic.get_name(), profile, true, partitions_.publisher)) return k->writer;
  Publisher* publisher = participant_->create_publisher(PUBLISHER_QOS_DEFAULT);
  DataWriter* w = nullptr;
  try {
    if (!publisher || !move_to(*publisher, partitions_.publisher)) refused(topic.get_name(), profile, true);
    w = make_writer(*publisher, topic, profile, nullptr);
  } catch (...) {
    if (publisher) participant_->delete_publisher(publisher);
    throw;
  }
  kept_.push_back(
      {topic.get_name(), profile, partitions_.publisher, publisher, w, nullptr, nullptr, true, ++take_ups_});
  return w;
}

DataReader* DdsContext::kept_reader(Topic& topic, const std::string& profile) {
  if (Kept* k = take_up(topic.get_name(), profile, false, partitions_.subscriber)) return k->reader;
  Subscriber* subscriber = participant_->create_subscriber(SUBSCRIBER_QOS_DEFAULT);
  DataReader* r = nullptr;
  try {
    if (!subscriber || !move_to(*subscriber, partitions_.subscriber)) refused(topic.get_name(), profile, false);
    r = make_reader(*subscriber, topic, profile, nullptr);
  } catch (...) {
    if (subscriber) participant_->delete_subscriber(subscriber);
    throw;
  }
  kept_.push_back(
      {topic.get_name(), profile, partitions_.subscriber, nullptr, nullptr, subscriber, r, true, ++take_ups_});
  return r;
}

bool DdsContext::park(const DomainEntity* endpoint) {
  for (auto& k : kept_)
    if (k.in_use && (k.writer == endpoint || k.reader == endpoint)) {
      k.in_use = false;
      // Left matched while idle (reuse_endpoints' `idle_matched` profiles), or moved away so
      // that nothing its remote writers publish comes to it.
      if (std::find(idle_matched_.begin(), idle_matched_.end(), k.profile) != idle_matched_.end()) return true;
      (void)move(k, {kClosingPartition});
      if (k.reader) drain(*k.reader);
      return true;
    }
  return false;
}

void DdsContext::delete_endpoints_since(EndpointMark mark) {
  if (reuse_) {
    // The kept ones are parked; one made with a listener was not kept, and is deleted below.
    writers_.erase(std::remove_if(writers_.begin() + static_cast<std::ptrdiff_t>(mark.writers), writers_.end(),
                                  [this](DataWriter* w) { return park(w); }),
                   writers_.end());
    readers_.erase(std::remove_if(readers_.begin() + static_cast<std::ptrdiff_t>(mark.readers), readers_.end(),
                                  [this](DataReader* r) { return park(r); }),
                   readers_.end());
  }
  // The hang above threatens any writer deleted while matched, so its publisher goes to the
  // closing partition first; the next job sets its own partitions (set_partitions).
  if (writers_.size() > mark.writers) unmatch_writers_before_deleting_them(*publisher_);
  while (writers_.size() > mark.writers) {
    (void)publisher_->delete_datawriter(writers_.back());
    writers_.pop_back();
  }
  while (readers_.size() > mark.readers) {
    // A reader with outstanding loans or read conditions is refused; pmuctl's verbs keep
    // neither once they return.
    (void)readers_.back()->delete_contained_entities();
    (void)subscriber_->delete_datareader(readers_.back());
    readers_.pop_back();
  }
}

DataWriter& DdsContext::default_partition_writer(Topic& topic, const DataWriterQos& qos) {
  if (!default_publisher_) default_publisher_ = participant_->create_publisher(PUBLISHER_QOS_DEFAULT);
  if (!default_publisher_)
    throw DdsError("cannot create a DDS publisher in the default partition for " + topic.get_name());
  DataWriter* w = default_publisher_->create_datawriter(&topic, qos);
  if (!w) {
    const std::string what = "cannot create a writer for " + topic.get_name() + " in the default partition";
    if (!secure_) throw DdsError(what);
    throw DdsError(what + " (DDS-Security: this identity's permissions may not allow publishing it there)");
  }
  return *w;
}

DataReader& DdsContext::default_partition_reader(Topic& topic, const DataReaderQos& qos, DataReaderListener* listener) {
  if (!default_subscriber_) default_subscriber_ = participant_->create_subscriber(SUBSCRIBER_QOS_DEFAULT);
  if (!default_subscriber_)
    throw DdsError("cannot create a DDS subscriber in the default partition for " + topic.get_name());
  DataReader* r = default_subscriber_->create_datareader(&topic, qos, listener);
  if (!r) {
    const std::string what = "cannot create a reader for " + topic.get_name() + " in the default partition";
    if (!secure_) throw DdsError(what);
    throw DdsError(what + " (DDS-Security: this identity's permissions may not allow subscribing to it there)");
  }
  return *r;
}

void DdsContext::too_small(const std::string& topic, const std::string& profile, bool publish,
                           const std::string& shortfall) const {
  throw DdsError(qos_file_ + ": <" + (publish ? "data_writer" : "data_reader") + " profile_name=\"" + profile +
                 "\"> (" + topic + "): " + shortfall +
                 ": raise its <resourceLimitsQos> (deploy/qos.xml says how each number is derived)");
}

void DdsContext::refused(const std::string& topic, const std::string& profile, bool publish) const {
  const std::string what = std::string("cannot create a ") + (publish ? "writer" : "reader") + " for " + topic +
                           " with QoS profile '" + profile + "'";
  if (!secure_) throw DdsError(what);
  // Fast DDS says why only in its log (its Access-Permissions plugin's "... partition not
  // found in rule"); the permissions document says it too, so the message can name it.
  const std::string verb = publish ? "publishing" : "subscribing to";
  const std::vector<std::string>& partitions = publish ? partitions_.publisher : partitions_.subscriber;
  const auto grant = topic_grant(security_, topic, publish);
  if (grant && !grant->allowed)
    throw DdsError(what + " (DDS-Security: this identity's permissions do not allow " + verb + " it: grant '" +
                   grant->grant + "' has no allow rule for " + topic + ")");
  if (grant) {
    if (const auto p = partition_not_granted(partitions, grant->partitions))
      throw PartitionNotGranted(what + " (DDS-Security: this identity's permissions do not allow " + verb + " it in " +
                                    partition_text(*p) + ": grant '" + grant->grant + "' allows it only in " +
                                    patterns_text(grant->partitions) + ")",
                                *p);
  }
  throw DdsError(what + " (DDS-Security: this identity's permissions may not allow " + verb + " it)");
}

}  // namespace pmu::dds
