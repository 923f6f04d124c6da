#include "pmuctl/verbs/role_verbs.hpp"

#include <unistd.h>

#include <CLI/CLI.hpp>
#include <cstdio>
#include <cstdlib>
#include <fastdds/dds/subscriber/SampleInfo.hpp>
#include <nlohmann/json.hpp>
#include <thread>

#include "pmu/command/command.hpp"
#include "pmu/dds/role_sample.hpp"
#include "pmu/idl/guarded_type.hpp"
#include "pmu/idl/role.h"
#include "pmu/idl/rolePubSubTypes.h"
#include "pmu/idl/topics.hpp"
#include "pmuctl/call/command_channel.hpp"
#include "pmuctl/call/context_lease.hpp"
#include "pmuctl/call/exit_status.hpp"
#include "pmuctl/call/service_presence.hpp"
#include "pmuctl/view/sample_json.hpp"

namespace pmu::tools {
namespace {

using namespace eprosima::fastdds::dds;
using Clock = std::chrono::steady_clock;

// Who asks, for the instance's audit log: the user and host this pmuctl runs as and on.
std::string requester() {
  const char* user = std::getenv("USER");
  char host[64] = {};
  if (::gethostname(host, sizeof host - 1) != 0) host[0] = '\0';
  return std::string(user && *user ? user : "?") + "@" + (host[0] ? host : "?");
}

}  // namespace

RoleCollector::RoleCollector(const GlobalOptions& o, pmu::dds::DdsContext& dds) : vehicle_(o.vehicle) {
  try {
    reader_ = &dds.reader(dds.topic(topics::kRole, TypeSupport(new idl::Guarded<pmu::v5::RoleHeartbeatPubSubType>())),
                          qos_profiles::kRole, this);
  } catch (const pmu::dds::DdsError& e) {
    if (!dds.secure()) throw;
    std::fprintf(stderr, "pmuctl: %s is not read, hot-standby pairs are not shown: %s\n", topics::kRole, e.what());
  }
}

RoleCollector::~RoleCollector() {
  if (reader_) reader_->set_listener(nullptr);
}

void RoleCollector::on_data_available(DataReader* reader) {
  pmu::v5::RoleHeartbeat s;
  SampleInfo info;
  while (reader->take_next_sample(&s, &info) == ReturnCode_t::RETCODE_OK) {
    const auto arrived = Clock::now();
    if (!info.valid_data) continue;
    // Typed once here; a sample whose enumerators are not the IDL's is not an instance's role.
    auto read = pmu::dds::read_role_heartbeat(s);
    if (!read.ok() || (vehicle_ && *vehicle_ != read.vehicle)) continue;
    auto key = std::make_pair(read.vehicle, read.report.name);
    std::lock_guard<std::mutex> lock(mutex_);
    last_[std::move(key)] = Last{std::move(read.report), arrived};
  }
}

std::vector<SeenInstance> RoleCollector::seen() const {
  const auto now = Clock::now();
  std::lock_guard<std::mutex> lock(mutex_);
  std::vector<SeenInstance> out;
  for (const auto& [key, last] : last_) out.push_back(SeenInstance{key.first, last.report, now - last.arrived});
  return out;
}

std::vector<SeenInstance> RoleCollector::seen(const std::string& vehicle) const {
  std::vector<SeenInstance> out;
  for (auto& s : seen())
    if (s.vehicle == vehicle) out.push_back(std::move(s));
  return out;
}

void RoleCollector::wait_for_peers(Clock::time_point deadline) const {
  while (!peers_heard(seen()) && Clock::now() < deadline) std::this_thread::sleep_for(std::chrono::milliseconds(20));
}

namespace {

int run_role_move(const GlobalOptions& o, const std::string& instance) {
  const double timeout = o.timeout.value_or(5.0);
  const auto deadline = wait_end(o, timeout);
  const std::string vehicle = o.vehicle.value_or(std::string());
  ContextLease lease(o, kPmuctlParticipant);
  pmu::dds::DdsContext& dds = *lease;
  DataReader& replies =
      dds.reader(dds.topic(topics::kRoleMoveReply, TypeSupport(new idl::Guarded<pmu::v5::RoleMoveReplyPubSubType>())),
                 qos_profiles::kCommand);
  DataWriter& writer =
      dds.writer(dds.topic(topics::kRoleMove, TypeSupport(new pmu::v5::RoleMovePubSubType())), qos_profiles::kCommand);
  if (const auto failed = wait_for_match(o, dds, writer, replies, vehicle, deadline, "answers role moves"))
    return *failed;

  pmu::v5::RoleMove m;
  const std::string id = request_id();
  m.request_id(id);
  m.vehicle(vehicle);
  m.instance(instance);
  m.requester(requester());
  // A move pmuctl gave up on is never made (docs/safety.md H9).
  m.expires_at(o.deadline_ns ? o.deadline_ns : epoch_ns_at(deadline));
  if (!writer.write(&m)) return fail(o, ExitStatus::NotDone, "the move could not be written to DDS");

  // Unanswered after 1 s: sent again with the same id, which the instance answers with its
  // first reply and never moves twice (interface.md 1.10), as commands are (2.4).
  constexpr auto kResendAfter = std::chrono::seconds(1);
  auto next_resend = Clock::now() + kResendAfter;
  const auto wait_until = deadline + std::chrono::milliseconds(500);
  while (Clock::now() < wait_until) {
    if (Clock::now() >= next_resend && Clock::now() < deadline) {
      (void)writer.write(&m);
      next_resend = Clock::now() + kResendAfter;
    }
    pmu::v5::RoleMoveReply r;
    SampleInfo info;
    while (replies.take_next_sample(&r, &info) == ReturnCode_t::RETCODE_OK) {
      if (!info.valid_data || r.request_id().to_string() != id || r.vehicle().to_string() != vehicle ||
          r.instance().to_string() != instance)
        continue;
      if (o.json) {
        Json j{{"request_id", id},
               {"vehicle", vehicle},
               {"instance", instance},
               {"result", r.accepted() ? "ACCEPTED" : "REFUSED"},
               {"reason", r.reason().to_string()}};
        std::printf("%s\n", j.dump(-1, ' ', false, nlohmann::json::error_handler_t::replace).c_str());
      }
      if (r.accepted())
        std::fprintf(stderr, "ACCEPTED: %s hands the bus over to its peer\n", service::printable(instance).c_str());
      else
        std::fprintf(stderr, "REFUSED: %s\n", service::printable(r.reason().to_string(), 127).c_str());
      return static_cast<int>(r.accepted() ? ExitStatus::Ok : ExitStatus::NotDone);
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  }
  char waited[96];
  std::snprintf(waited, sizeof waited, " within %.1f s (request ", timeout);
  const std::string message = "no reply from instance " + service::printable(instance) + " of " +
                              vehicle_text(vehicle) + waited + id +
                              "): no such instance, or it is not one of a pair (pmuctl list shows the pair)";
  std::fprintf(stderr, "pmuctl: %s\n", message.c_str());
  if (o.json) {
    Json j{{"request_id", id},  {"vehicle", vehicle}, {"instance", instance},
           {"result", nullptr}, {"reason", message},  {"exit_status", static_cast<int>(ExitStatus::NoAnswer)}};
    std::printf("%s\n", j.dump(-1, ' ', false, nlohmann::json::error_handler_t::replace).c_str());
  }
  return static_cast<int>(ExitStatus::NoAnswer);
}

class RoleVerbs : public Verb {
 public:
  explicit RoleVerbs(CLI::App& app) {
    role_ = app.add_subcommand("role", "Hot standby: the role of an instance of a pair");
    role_->require_subcommand(1);
    move_ = role_->add_subcommand(
        "move", "Ask the ACTIVE instance INSTANCE to hand the bus to its peer (exit 0 accepted, 1 refused)");
    move_->add_option("instance", instance_, "The instance's name (its config's redundancy name; pmuctl list)")
        ->required();
  }
  bool chosen() const override { return role_->parsed(); }
  std::optional<int> check(const GlobalOptions& g) override {
    if (instance_.empty() || instance_.size() > 63)
      return fail(g, ExitStatus::BadUsage,
                  "role move: INSTANCE '" + service::printable(instance_) + "': an instance name of 1 to 63 bytes");
    return std::nullopt;
  }
  int run(GlobalOptions& g) override { return run_role_move(g, instance_); }

 private:
  CLI::App* role_;
  CLI::App* move_;
  std::string instance_;
};

}  // namespace

std::unique_ptr<Verb> add_role_verbs(CLI::App& app) { return std::make_unique<RoleVerbs>(app); }

}  // namespace pmu::tools
