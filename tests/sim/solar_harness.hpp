#pragma once
// Batteries and MPPTs on one SolarPlant, driven by a fake clock: the test moves `now` by
// hand and reads back the frames the models sent, decoded with codec::canopen::decode as
// the service would.

#include <gtest/gtest.h>

#include <chrono>
#include <cstdint>
#include <map>
#include <memory>
#include <optional>
#include <set>
#include <string>
#include <utility>
#include <vector>

#include "pmu/codec/canopen.hpp"
#include "pmu/sim/battery_model.hpp"
#include "pmu/sim/mppt_model.hpp"
#include "pmu/sim/solar_plant.hpp"

namespace pmu::sim::test {

using namespace std::chrono_literals;
using codec::canopen::CanOpenMessage;

struct SentFrame {
  TimePoint at;
  codec::CanFrame frame;
};

// (COB-ID, subindex): what identifies one value of the document's tables on the wire.
using Key = std::pair<std::uint16_t, std::uint8_t>;

class SolarHarness {
 public:
  explicit SolarHarness(const SolarWorld& world = SolarWorld{}) : plant(std::make_shared<SolarPlant>(world, start)) {}

  // Arbitrary, far from the epoch: nothing may depend on the clock's origin.
  const TimePoint start = TimePoint{} + 1000h;
  TimePoint now = start;
  std::vector<SentFrame> sent;
  std::shared_ptr<SolarPlant> plant;
  std::vector<std::unique_ptr<BatteryModel>> batteries;  // after what their sinks use
  std::vector<std::unique_ptr<MpptModel>> mppts;

  BatteryModel& add(const BatterySimConfig& c) {
    batteries.push_back(std::make_unique<BatteryModel>(c, plant, sink(), now));
    return *batteries.back();
  }
  MpptModel& add(const MpptSimConfig& c) {
    mppts.push_back(std::make_unique<MpptModel>(c, plant, sink(), now));
    return *mppts.back();
  }

  void tick() {
    for (auto& b : batteries) b->tick(now);
    for (auto& m : mppts) m->tick(now);
  }
  // Moves the fake clock in `step`s (one tick each) until `total` has passed.
  void run(Duration total, Duration step = 10ms) {
    const TimePoint end = now + total;
    while (now < end) {
      now = std::min(now + step, end);
      tick();
    }
  }

  // Frames sent so far, decoded; every one must decode. Clears the list.
  std::vector<CanOpenMessage> take() {
    std::vector<CanOpenMessage> out;
    for (const auto& s : sent) {
      const auto m = codec::canopen::decode(s.frame);
      EXPECT_TRUE(m.ok()) << m.error().describe();
      if (m) out.push_back(*m);
    }
    sent.clear();
    return out;
  }

 private:
  FrameSink sink() {
    return [this](const codec::CanFrame& f) { sent.push_back({now, f}); };
  }
};

inline Key key_of(const CanOpenMessage& m) {
  // 0x202's index and subindex are "Don't Care": one value per COB-ID.
  return {m.cob_id, m.cob_id == 0x202 ? std::uint8_t{0} : m.subindex};
}

// The last value of each name seen (for 0x482: "cell_voltage_<n>").
inline std::map<std::string, double> latest(const std::vector<CanOpenMessage>& msgs) {
  std::map<std::string, double> v;
  for (const auto& m : msgs) {
    if (m.cob_id == 0x482) {
      v["cell_voltage_" + std::to_string(m.subindex)] = m.fields[1].value;
      continue;
    }
    for (std::uint8_t i = 0; i < m.field_count; ++i) v[std::string(m.fields[i].name)] = m.fields[i].value;
  }
  return v;
}

}  // namespace pmu::sim::test
