#pragma once
// Hot standby in pmuctl (interface.md 1.10, 3.2): pmu/role read beside `list` and `preflight`
// (RoleCollector), and `role move INSTANCE`, which asks an instance to hand the bus to its peer
// on pmu/role_move and waits for its pmu/role_move_reply.

#include <fastdds/dds/subscriber/DataReader.hpp>
#include <fastdds/dds/subscriber/DataReaderListener.hpp>

#include <chrono>
#include <map>
#include <memory>
#include <mutex>
#include <string>
#include <utility>
#include <vector>

#include "pmu/dds/dds_context.hpp"
#include "pmuctl/verbs/state_verbs.hpp"
#include "pmuctl/verbs/verb.hpp"
#include "pmuctl/view/role_view.hpp"

namespace pmu::tools {

// Every pmu/role sample of the vehicles the call reads (--vehicle, or all), from the
// constructor on, each instance's last one stamped with the steady time it arrived: a sample's
// age is pmuctl's own measure, whatever the writer's clock (role_view.hpp says why).
// Lifetime: made after the call's ContextLease and gone before it (its reader's listener is
// removed in the destructor). Fast DDS's thread writes, the call's thread reads seen().
class RoleCollector final : public eprosima::fastdds::dds::DataReaderListener {
 public:
  // No reader when the permissions do not grant pmu/role: said once on stderr, nothing seen.
  RoleCollector(const GlobalOptions& o, pmu::dds::DdsContext& dds);
  ~RoleCollector() override;
  RoleCollector(const RoleCollector&) = delete;
  RoleCollector& operator=(const RoleCollector&) = delete;

  // Each instance heard, by vehicle and name, its age now.
  std::vector<SeenInstance> seen() const;
  // The instances of one vehicle.
  std::vector<SeenInstance> seen(const std::string& vehicle) const;

  // Waits until every instance heard has its peer heard too (role_view.hpp, peers_heard), or
  // until `deadline`: the instances of a pair come as discovery finds them, one after the other.
  void wait_for_peers(std::chrono::steady_clock::time_point deadline) const;

  void on_data_available(eprosima::fastdds::dds::DataReader* reader) override;

 private:
  struct Last {
    redundancy::RoleReport report;
    std::chrono::steady_clock::time_point arrived;
  };
  std::optional<std::string> vehicle_;
  eprosima::fastdds::dds::DataReader* reader_ = nullptr;
  mutable std::mutex mutex_;
  std::map<std::pair<std::string, std::string>, Last> last_;  // (vehicle, name)
};

// role move INSTANCE.
std::unique_ptr<Verb> add_role_verbs(CLI::App& app);

}  // namespace pmu::tools
