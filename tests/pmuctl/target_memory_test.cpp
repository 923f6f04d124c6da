// Which PMU an agent's worker remembers for a vehicle (tools/pmuctl/agent/target_memory.hpp):
// per vehicle and per --bus/--address filter, for kKeptFor after it was found and no longer,
// forgotten on request; and which REJECTED reasons say the remembered PMU is gone.
#include <gtest/gtest.h>

#include <chrono>

#include "pmuctl/agent/target_memory.hpp"

namespace {

using pmu::tools::says_target_gone;
using pmu::tools::Target;
using pmu::tools::TargetMemory;
using pmu::tools::TargetQuery;
using namespace std::chrono_literals;

const TargetMemory::Clock::time_point t0{};

TEST(TargetMemory, RecallsWhatWasFoundForTheSameQueryAlone) {
  TargetMemory m;
  m.remember({"uav1", "", std::nullopt}, {"can0", 1}, t0);
  const auto got = m.recall({"uav1", "", std::nullopt}, t0 + 1s);
  ASSERT_TRUE(got);
  EXPECT_EQ(got->bus, "can0");
  EXPECT_EQ(got->address, 1);
  struct Other {
    const char* why;
    TargetQuery query;
  };
  for (const auto& o : std::initializer_list<Other>{
           {"another vehicle", {"uav2", "", std::nullopt}},
           {"the unnamed vehicle", {"", "", std::nullopt}},
           {"a --bus filter", {"uav1", "can0", std::nullopt}},
           {"an --address filter", {"uav1", "", 1}},
       })
    EXPECT_FALSE(m.recall(o.query, t0 + 1s)) << o.why;
}

TEST(TargetMemory, KeepsAFoundPmuForKeptForAndNoLonger) {
  TargetMemory m;
  const TargetQuery q{"uav1", "", std::nullopt};
  m.remember(q, {"can0", 1}, t0);
  EXPECT_TRUE(m.recall(q, t0 + TargetMemory::kKeptFor - 1ms));
  EXPECT_FALSE(m.recall(q, t0 + TargetMemory::kKeptFor));
  EXPECT_FALSE(m.recall(q, t0 - 1s)) << "a time before it was found";
  // Found again: kept from then on, at its new place.
  m.remember(q, {"can1", 7}, t0 + TargetMemory::kKeptFor);
  const auto got = m.recall(q, t0 + TargetMemory::kKeptFor + 1s);
  ASSERT_TRUE(got);
  EXPECT_EQ(got->bus, "can1");
  EXPECT_EQ(got->address, 7);
}

TEST(TargetMemory, ForgetsOnRequestOnlyThatQuery) {
  TargetMemory m;
  m.remember({"uav1", "", std::nullopt}, {"can0", 1}, t0);
  m.remember({"uav2", "", std::nullopt}, {"can0", 1}, t0);
  m.forget({"uav1", "", std::nullopt});
  EXPECT_FALSE(m.recall({"uav1", "", std::nullopt}, t0));
  EXPECT_TRUE(m.recall({"uav2", "", std::nullopt}, t0));
}

TEST(TargetMemory, OnlyTheServicesNotSeenOfThatDeviceSaysItIsGone) {
  struct Row {
    const char* reason;
    bool gone;
  };
  const Target at{"can0", 1};
  for (const auto& r : std::initializer_list<Row>{
           {"device 1 not seen on can0", true},
           {"device 7 not seen on can0", false},  // another device
           {"device 1 not seen on can1", false},  // another bus
           {"device 1 on can0 is not ready: its firmware and configuration have not been read yet", false},
           {"expired before it could be sent", false},
           {"", false},
       })
    EXPECT_EQ(says_target_gone(r.reason, at), r.gone) << r.reason;
}

}  // namespace
