// The parameter server under a fake clock: lists paced and not restarted by a flood, reads,
// and exactly one PARAM_VALUE for every PARAM_SET whatever the service answers.
#include <gtest/gtest.h>

#include <algorithm>

#include "pmu/mavlink_params/param_server.hpp"
#include "pmu/mavlink_params/status_text.hpp"

namespace pmu::mavlink_params {
namespace {

using namespace std::chrono_literals;
using service::CommandResult;
using service::ConfirmRule;

const Time t0 = Time{} + 1h;
const Sender qgc{255, 190};
const Sender mavproxy{255, 1};

// A PMU as the simulator reads: every setting known.
baseline::Settings device() {
  baseline::Settings s;
  s[Setting::AvionicsVoltage] = 240;
  s[Setting::PayloadVoltage] = 120;
  s[Setting::ServoVoltage] = 60;
  s[Setting::BatteryVoltage] = 252;
  s[Setting::PacketPeriod] = 5;
  s[Setting::PacketsStreamed] = 0x1F;
  s[Setting::TemperatureOffset] = 0;
  s[Setting::UpperTemperatureLimit] = 80;
  s[Setting::PowerUpState] = 0x03;
  s[Setting::CrankingTime] = 50;
  s[Setting::CanAddress] = 1;
  s[Setting::Outputs] = 0x03;
  s[Setting::GenerationEnabled] = 1;
  return s;
}

ParamServer server(std::size_t pmus = 2, ConfirmSet confirm = {}) {
  ParamServerConfig c;
  c.pmu_count = pmus;
  c.confirm = confirm;
  ParamServer s(c);
  for (std::size_t i = 0; i < pmus; ++i) s.set_device(i, device());
  return s;
}

std::vector<mavlink::ParamValue> values(const Output& out) {
  std::vector<mavlink::ParamValue> v;
  for (const auto& m : out.send)
    if (const auto* p = std::get_if<mavlink::ParamValue>(&m)) v.push_back(*p);
  return v;
}
std::string texts(const Output& out) {
  std::string t;
  for (const auto& m : out.send)
    if (const auto* s = std::get_if<mavlink::Statustext>(&m)) t += s->text;
  return t;
}

mavlink::ParamSet set_of(std::string name, float value) {
  mavlink::ParamSet m;
  m.target_system = 1;
  m.target_component = 180;
  m.param_id = std::move(name);
  m.param_value = value;
  return m;
}

// Polls every 10 ms from `from` for `span`; returns what went out, with when.
std::vector<std::pair<Time, mavlink::ParamValue>> run(ParamServer& s, Time from, std::chrono::milliseconds span) {
  std::vector<std::pair<Time, mavlink::ParamValue>> sent;
  for (auto t = from; t <= from + span; t += 10ms)
    for (const auto& v : values(s.poll(t))) sent.emplace_back(t, v);
  return sent;
}

TEST(ParamList, SendsEveryKnownParameterOnceAtThePace) {
  auto s = server(2);
  s.poll(t0);
  s.on_request_list(qgc, t0);
  const auto sent = run(s, t0, 5000ms);
  ASSERT_EQ(sent.size(), 2 * kSettingCount);
  std::set<std::uint16_t> indices;
  for (const auto& [t, v] : sent) {
    indices.insert(v.param_index);
    EXPECT_EQ(v.param_count, 2 * kSettingCount);
    EXPECT_EQ(v.param_type, mavlink::mav_param_type::kReal32);
    EXPECT_EQ(param_from_name(v.param_id, 2), param_from_index(v.param_index, 2));
  }
  EXPECT_EQ(indices.size(), 2 * kSettingCount);
  // 10 a second, at most two at once after a quiet while: 26 take 2.4 s or more.
  EXPECT_GE(sent.back().first - sent.front().first, 2400ms);
  for (auto t = t0; t < t0 + 4000ms; t += 1000ms) {
    const auto in_second =
        std::count_if(sent.begin(), sent.end(), [&](const auto& e) { return e.first >= t && e.first < t + 1000ms; });
    EXPECT_LE(in_second, 11) << "second at " << (t - t0).count();
  }
  EXPECT_EQ(s.counters().values_sent, 2 * kSettingCount);
}

TEST(ParamList, AFloodOfListRequestsDoesNotRestartOrSpeedUpTheList) {
  auto s = server(2);
  s.poll(t0);
  s.on_request_list(qgc, t0);
  std::vector<mavlink::ParamValue> sent;
  for (auto t = t0; t <= t0 + 5000ms; t += 10ms) {
    // A ground station that asks again and again while the list runs (2.5 s at the pace).
    if (t < t0 + 2000ms) s.on_request_list(qgc, t);
    for (const auto& v : values(s.poll(t))) sent.push_back(v);
  }
  EXPECT_EQ(sent.size(), 2 * kSettingCount) << "each parameter once";
  EXPECT_EQ(s.counters().list_requests_merged, s.counters().list_requests - 1);
}

TEST(ParamList, ASecondGroundStationGetsEveryParameterWithoutAFaster) {
  auto s = server(1);
  s.poll(t0);
  s.on_request_list(qgc, t0);
  auto first = run(s, t0, 500ms);
  ASSERT_FALSE(first.empty());
  ASSERT_LT(first.size(), kSettingCount);
  s.on_request_list(mavproxy, t0 + 500ms);
  const auto rest = run(s, t0 + 510ms, 5000ms);
  std::set<std::uint16_t> after_second;
  for (const auto& [t, v] : rest) after_second.insert(v.param_index);
  EXPECT_EQ(after_second.size(), kSettingCount) << "the second sender gets all of them";
  EXPECT_EQ(first.size() + rest.size(), kSettingCount + first.size()) << "what went before goes once more, no more";
}

TEST(ParamList, ValuesNotKnownAreNotSent) {
  ParamServerConfig c;
  c.pmu_count = 2;
  ParamServer s(c);
  auto partial = device();
  partial[Setting::CrankingTime].reset();
  s.set_device(0, partial);  // PMU 2 never read
  s.poll(t0);
  s.on_request_list(qgc, t0);
  const auto sent = run(s, t0, 5000ms);
  EXPECT_EQ(sent.size(), kSettingCount - 1);
  for (const auto& [t, v] : sent) EXPECT_NE(v.param_id, "PMU1_CRANK_TIME");
  EXPECT_EQ(s.counters().values_skipped, kSettingCount + 1);
  s.forget_device(0);
  s.on_request_list(qgc, t0 + 6s);
  EXPECT_TRUE(run(s, t0 + 6s, 3000ms).empty());
}

TEST(ParamList, APmuHeardLaterAddsItsParametersAfterTheFirstsWhoseIndicesStay) {
  auto s = server(1);
  s.poll(t0);
  s.grow(0);  // a smaller count changes nothing
  s.grow(2);
  s.set_device(1, device());
  s.grow(1);
  s.on_request_list(qgc, t0);
  const auto sent = run(s, t0, 5000ms);
  ASSERT_EQ(sent.size(), 2 * kSettingCount);
  EXPECT_EQ(s.param_count(), 2 * kSettingCount);
  for (const auto& [t, v] : sent) {
    EXPECT_EQ(v.param_count, 2 * kSettingCount);
    EXPECT_EQ(param_from_index(v.param_index, 2), param_from_name(v.param_id, 2)) << v.param_id;
  }
  // Ten PMUs heard: the tenth has no parameters (the prefix has one digit).
  s.grow(10);
  EXPECT_EQ(s.param_count(), kMaxPmus * kSettingCount);
}

TEST(ParamList, AFloodFromManySendersOfListsAndReadsIsCountedAndCarriedAtThePace) {
  auto s = server(9);
  s.poll(t0);
  std::size_t sent = 0;
  for (int i = 0; i < 10000; ++i) {
    const auto t = t0 + std::chrono::microseconds(100 * i);  // 10,000 a second
    const Sender from{static_cast<std::uint8_t>(i % 50), 190};
    if (i % 10 == 0) s.on_request_list(from, t);
    mavlink::ParamRequestRead read;
    read.param_index = static_cast<std::int16_t>(i % 200);  // some beyond the table
    s.on_request_read(from, read, t);
    sent += values(s.poll(t)).size();
  }
  EXPECT_LE(sent, 12U) << "one second at 10 a second";
  EXPECT_EQ(s.counters().list_requests, 1000U);
  EXPECT_EQ(s.counters().reads, 10000U);
  EXPECT_GT(s.counters().list_requests_merged, 900U);
  EXPECT_GT(s.counters().reads_unanswered, 0U);
}

TEST(ParamRead, ByNameAndByIndexOnceEachAndNotForUnknownNames) {
  auto s = server(2);
  s.poll(t0);
  mavlink::ParamRequestRead by_name;
  by_name.param_id = "PMU2_TEMP_UPPER";
  mavlink::ParamRequestRead by_index;
  by_index.param_index = 0;
  mavlink::ParamRequestRead unknown;
  unknown.param_id = "PMU3_TEMP_UPPER";
  s.on_request_read(qgc, by_name, t0);
  s.on_request_read(qgc, by_name, t0);
  s.on_request_read(qgc, by_index, t0);
  s.on_request_read(qgc, unknown, t0);
  const auto sent = run(s, t0, 2000ms);
  ASSERT_EQ(sent.size(), 2U);
  EXPECT_EQ(sent[0].second.param_id, "PMU1_AVION_V");
  EXPECT_FLOAT_EQ(sent[0].second.param_value, 24.0F);
  EXPECT_EQ(sent[1].second.param_id, "PMU2_TEMP_UPPER");
  EXPECT_EQ(sent[1].second.param_index, kSettingCount + 7);
  EXPECT_EQ(s.counters().reads_unanswered, 1U);
}

// What the service answers a set with, and the one PARAM_VALUE that answers the PARAM_SET.
struct SetCase {
  const char* name;
  CommandResult result;
  float expected;  // the value of the one PARAM_VALUE
  bool text;       // a STATUSTEXT says why
};

class ParamSetReply : public testing::TestWithParam<SetCase> {};

TEST_P(ParamSetReply, ExactlyOneParamValueWithTheDevicesValueAfterTheSet) {
  const auto c = GetParam();
  auto s = server(1);
  const auto asked = s.on_param_set(qgc, set_of("PMU1_AVION_V", 20.0F), t0);
  EXPECT_TRUE(asked.send.empty()) << "nothing until the service answers";
  ASSERT_TRUE(asked.request);
  EXPECT_EQ(asked.request->raw, 200U);
  EXPECT_FALSE(asked.request->confirm);
  EXPECT_TRUE(std::holds_alternative<service::action::SetParameter>(asked.request->action()));
  EXPECT_TRUE(values(s.on_set_reply(asked.request->tag, CommandResult::InProgress, "working")).empty());
  const auto answer = s.on_set_reply(asked.request->tag, c.result, "bus error: read back 24.0 V");
  const auto v = values(answer);
  ASSERT_EQ(v.size(), 1U);
  EXPECT_EQ(v[0].param_id, "PMU1_AVION_V");
  EXPECT_FLOAT_EQ(v[0].param_value, c.expected);
  EXPECT_EQ(!texts(answer).empty(), c.text);
  if (c.text) {
    EXPECT_NE(texts(answer).find("read back"), std::string::npos) << "the service's reason";
  }
  // A second reply for the same set, and the timeout, send nothing more.
  EXPECT_TRUE(s.on_set_reply(asked.request->tag, c.result, "again").send.empty());
  EXPECT_TRUE(values(s.poll(t0 + 60s)).empty());
  EXPECT_EQ(s.counters().replies_unmatched, 1U);
}

INSTANTIATE_TEST_SUITE_P(Results, ParamSetReply,
                         testing::Values(SetCase{"completed", CommandResult::Completed, 20.0F, false},
                                         SetCase{"denied", CommandResult::Denied, 24.0F, true},
                                         SetCase{"rejected", CommandResult::Rejected, 24.0F, true},
                                         SetCase{"failed", CommandResult::Failed, 24.0F, true},
                                         SetCase{"timeout", CommandResult::Timeout, 24.0F, true},
                                         SetCase{"unsupported", CommandResult::Unsupported, 24.0F, true}),
                         [](const auto& test_info) { return std::string(test_info.param.name); });

TEST(ParamSet, NoReplyFromTheServiceIsAnsweredOnceWithTheOldValueAtTheTimeout) {
  auto s = server(1);
  const auto asked = s.on_param_set(qgc, set_of("PMU1_AVION_V", 20.0F), t0);
  ASSERT_TRUE(asked.request);
  EXPECT_TRUE(s.poll(t0 + 11s).send.empty());
  const auto out = s.poll(t0 + 12s);
  const auto v = values(out);
  ASSERT_EQ(v.size(), 1U);
  EXPECT_FLOAT_EQ(v[0].param_value, 24.0F);
  EXPECT_NE(texts(out).find("no reply"), std::string::npos);
  EXPECT_TRUE(s.poll(t0 + 13s).send.empty());
  EXPECT_TRUE(s.on_set_reply(asked.request->tag, CommandResult::Completed, "").send.empty()) << "late";
  EXPECT_EQ(s.counters().sets_timed_out, 1U);
}

TEST(ParamSet, ARetransmissionWhileItRunsIsNeitherSentNorAnsweredTwice) {
  auto s = server(1);
  const auto first = s.on_param_set(qgc, set_of("PMU1_AVION_V", 20.0F), t0);
  ASSERT_TRUE(first.request);
  const auto again = s.on_param_set(qgc, set_of("PMU1_AVION_V", 20.0F), t0 + 1s);
  EXPECT_FALSE(again.request);
  EXPECT_TRUE(again.send.empty());
  EXPECT_EQ(values(s.on_set_reply(first.request->tag, CommandResult::Completed, "")).size(), 1U);
  EXPECT_EQ(s.counters().sets_sent, 1U);
  EXPECT_EQ(s.counters().sets_merged, 1U);
}

TEST(ParamSet, RefusedHereWithTheOldValueAndAReasonAndNothingSent) {
  struct Case {
    const char* name;
    float value;
    std::uint8_t type;
    float expected;
    const char* why;
  };
  for (const auto& c :
       {Case{"PMU1_AVION_V", 30.0F, 9, 24.0F, "out of range"}, Case{"PMU1_AVION_V", 23.05F, 9, 24.0F, "multiple"},
        Case{"PMU1_AVION_V", 20.0F, 6, 24.0F, "REAL32"}, Case{"PMU1_CAN_ADDR", 7.0F, 9, 1.0F, "read-only"},
        Case{"PMU1_TEMP_UPPER", 0.0F, 9, 80.0F, "rule thermal_shutdown"},
        Case{"PMU1_POWERUP", 2.0F, 9, 3.0F, "rule power_up_avionics_off"},
        Case{"PMU1_PKT_STREAM", 0.0F, 9, 31.0F, "rule stop_streaming"},
        Case{"PMU1_OUTPUTS", 2.0F, 9, 3.0F, "rule disable_avionics"}}) {
    SCOPED_TRACE(c.name);
    auto s = server(1);
    auto m = set_of(c.name, c.value);
    m.param_type = c.type;
    const auto out = s.on_param_set(qgc, m, t0);
    EXPECT_FALSE(out.request);
    const auto v = values(out);
    ASSERT_EQ(v.size(), 1U);
    EXPECT_EQ(v[0].param_id, c.name);
    EXPECT_FLOAT_EQ(v[0].param_value, c.expected);
    EXPECT_NE(texts(out).find(c.why), std::string::npos) << texts(out);
    EXPECT_EQ(s.counters().sets_refused, 1U);
  }
}

TEST(ParamSet, AConfiguredRuleIsSentConfirmedAndOthersStillRefused) {
  ConfirmSet confirm{};
  confirm[static_cast<std::size_t>(ConfirmRule::ThermalShutdown)] = true;
  auto s = server(1, confirm);
  const auto out = s.on_param_set(qgc, set_of("PMU1_TEMP_UPPER", 60.0F), t0);
  ASSERT_TRUE(out.request);
  EXPECT_TRUE(out.request->confirm);
  EXPECT_FALSE(s.on_param_set(qgc, set_of("PMU1_PKT_STREAM", 0.0F), t0).request);
  // A set no rule covers goes unconfirmed: the service judges it again.
  const auto plain = s.on_param_set(qgc, set_of("PMU1_PAYLD_V", 13.0F), t0);
  ASSERT_TRUE(plain.request);
  EXPECT_FALSE(plain.request->confirm);
}

TEST(ParamSet, UnknownNamesAreNotAnsweredAndTheDevicesValueIsAnsweredAtOnce) {
  auto s = server(1);
  EXPECT_TRUE(s.on_param_set(qgc, set_of("PMU2_AVION_V", 20.0F), t0).send.empty());
  EXPECT_TRUE(s.on_param_set(qgc, set_of("SYSID_THISMAV", 2.0F), t0).send.empty());
  EXPECT_EQ(s.counters().sets_unknown_name, 2U);
  // A parameter file loaded back: the same values, nothing to the service.
  const auto same = s.on_param_set(qgc, set_of("PMU1_CAN_ADDR", 1.0F), t0);
  EXPECT_FALSE(same.request);
  ASSERT_EQ(values(same).size(), 1U);
  EXPECT_FLOAT_EQ(values(same)[0].param_value, 1.0F);
  EXPECT_TRUE(texts(same).empty());
}

TEST(ParamSet, SetsInFlightAreBoundedAndCounted) {
  auto s = server(9);
  std::size_t sent = 0;
  for (std::size_t pmu = 0; pmu < 9; ++pmu)
    for (const char* suffix : {"AVION_V", "PAYLD_V"})
      if (s.on_param_set(qgc, set_of("PMU" + std::to_string(pmu + 1) + "_" + suffix, 13.0F), t0).request) ++sent;
  EXPECT_EQ(sent, 16U);
  EXPECT_EQ(s.counters().sets_refused, 2U);
}

TEST(ParamSet, AChangeByAnotherClientIsSentAgain) {
  auto s = server(1);
  s.poll(t0);
  auto changed = device();
  changed[Setting::AvionicsVoltage] = 200;
  s.set_device(0, changed);
  const auto sent = run(s, t0, 1000ms);
  ASSERT_EQ(sent.size(), 1U);
  EXPECT_FLOAT_EQ(sent[0].second.param_value, 20.0F);
}

TEST(ParamSet, TheDevicesNewValueArrivingBeforeTheReplyIsNotASecondAnswer) {
  auto s = server(1);
  s.poll(t0);
  const auto asked = s.on_param_set(qgc, set_of("PMU1_AVION_V", 20.0F), t0);
  ASSERT_TRUE(asked.request);
  auto changed = device();
  changed[Setting::AvionicsVoltage] = 200;  // pmu/config after the set, before the reply
  s.set_device(0, changed);
  EXPECT_TRUE(run(s, t0, 1000ms).empty());
  EXPECT_EQ(values(s.on_set_reply(asked.request->tag, CommandResult::Completed, "")).size(), 1U);
}

TEST(StatusText, LongReasonsGoInChunksOfOneTextAndAreCut) {
  const std::string text(120, 'a');
  const auto three = status_text(mavlink::mav_severity::kWarning, text, 7);
  ASSERT_EQ(three.size(), 3U);
  for (std::size_t i = 0; i < three.size(); ++i) {
    EXPECT_EQ(three[i].id, 7);
    EXPECT_EQ(three[i].chunk_seq, i);
    EXPECT_EQ(three[i].severity, mavlink::mav_severity::kWarning);
  }
  EXPECT_EQ(three[0].text.size() + three[1].text.size() + three[2].text.size(), 120U);
  const auto whole = status_text(mavlink::mav_severity::kInfo, std::string(100, 'b'), 8);
  ASSERT_EQ(whole.size(), 3U) << "two full chunks and the empty one that ends the text";
  EXPECT_TRUE(whole[2].text.empty());
  const auto one = status_text(mavlink::mav_severity::kInfo, "short\n\x1b[2J", 9);
  ASSERT_EQ(one.size(), 1U);
  EXPECT_EQ(one[0].id, 0);
  EXPECT_EQ(one[0].text, "short??[2J") << "a peer cannot move a ground station's cursor";
  const auto control = status_text(mavlink::mav_severity::kInfo, std::string("a\nb\x1b", 4), 9);
  EXPECT_EQ(control.at(0).text, "a?b?");
  const auto cut = status_text(mavlink::mav_severity::kInfo, std::string(1000, 'c'), 10);
  ASSERT_EQ(cut.size(), kMaxChunks);
  EXPECT_EQ(cut.back().text.substr(cut.back().text.size() - 3), "...");
}

}  // namespace
}  // namespace pmu::mavlink_params
