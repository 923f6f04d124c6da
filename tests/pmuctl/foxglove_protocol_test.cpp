// `pmuctl serve`'s Foxglove WebSocket protocol pieces (foxglove_protocol.hpp) against the
// spec (github.com/foxglove/ws-protocol docs/spec.md; the field names are those of
// @foxglove/ws-protocol's types.ts): serverInfo, advertise, status, MessageData's byte
// layout, and what the server answers to each kind of client message.
#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

#include "pmuctl/serve/foxglove_protocol.hpp"

namespace pmu::tools::foxglove {
namespace {

using nlohmann::json;

json parsed(const std::string& text) {
  const json j = json::parse(text, nullptr, false);
  EXPECT_FALSE(j.is_discarded()) << text;
  return j;
}

// The one status message of a reply list, parsed.
json only_status(const std::vector<std::string>& replies) {
  EXPECT_EQ(replies.size(), 1u);
  if (replies.empty()) return json{};
  const json j = parsed(replies[0]);
  EXPECT_EQ(j["op"], "status");
  return j;
}

TEST(FoxgloveProtocol, ServerInfoHasNameAndTheTimeCapability) {
  const json j = parsed(server_info_json("pmuctl serve (pmu-dds)"));
  EXPECT_EQ(j["op"], "serverInfo");
  EXPECT_EQ(j["name"], "pmuctl serve (pmu-dds)");
  EXPECT_EQ(j["capabilities"], json::array({"time"}));
}

TEST(FoxgloveProtocol, TimeIsOpcodeTwoAndNanosecondsLittleEndian) {
  const std::string t = time_message(1700000000123456789ull);
  const std::string want("\x02\x15\xCD\x85\x3D\xFE\x9C\x97\x17", 9);
  EXPECT_EQ(t, want);
  EXPECT_EQ(time_message(0), std::string(9, '\0').replace(0, 1, "\x02"));
}

TEST(FoxgloveProtocol, SubprotocolIsTheFirstOfferedThatTheServerSpeaks) {
  struct Case {
    std::vector<std::string> offered;
    std::string_view chosen;
  };
  const Case cases[] = {
      {{"foxglove.websocket.v1"}, "foxglove.websocket.v1"},
      {{"foxglove.sdk.v1"}, "foxglove.sdk.v1"},
      {{"foxglove.sdk.v1", "foxglove.websocket.v1"}, "foxglove.sdk.v1"},
      {{"foxglove.websocket.v1", "foxglove.sdk.v1"}, "foxglove.websocket.v1"},
      {{"chat", "foxglove.sdk.v1"}, "foxglove.sdk.v1"},
      {{"foxglove.websocket.v2", "FOXGLOVE.SDK.V1"}, ""},
      {{}, ""},
  };
  for (const auto& c : cases) EXPECT_EQ(choose_subprotocol(c.offered), c.chosen) << c.offered.size();
}

TEST(FoxgloveProtocol, AdvertiseListsEveryChannelAsCdrWithOmgIdlSchema) {
  const std::string_view idl = "module pmu { struct Voltages { float avionics; }; };";
  const json j = parsed(
      advertise_json({{0, "pmu/voltages", "pmu::v5::Voltages", idl}, {5, "pmu/health", "pmu::v5::Health", "x"}}));
  EXPECT_EQ(j["op"], "advertise");
  ASSERT_EQ(j["channels"].size(), 2u);
  const json& c = j["channels"][0];
  EXPECT_EQ(c["id"], 0);
  EXPECT_EQ(c["topic"], "pmu/voltages");
  EXPECT_EQ(c["encoding"], "cdr");
  EXPECT_EQ(c["schemaName"], "pmu::v5::Voltages");
  EXPECT_EQ(c["schemaEncoding"], "omgidl");
  EXPECT_EQ(c["schema"], idl);
  EXPECT_EQ(j["channels"][1]["id"], 5);
  EXPECT_EQ(j["channels"][1]["topic"], "pmu/health");
}

TEST(FoxgloveProtocol, StatusCarriesLevelNumberAndMessage) {
  struct Case {
    StatusLevel level;
    int number;
  };
  for (const Case c : {Case{StatusLevel::Info, 0}, Case{StatusLevel::Warning, 1}, Case{StatusLevel::Error, 2}}) {
    const json j = parsed(status_json(c.level, "dropped 3"));
    EXPECT_EQ(j["op"], "status");
    EXPECT_EQ(j["level"], c.number);
    EXPECT_EQ(j["message"], "dropped 3");
  }
  // A message quoting a client's bytes that are not UTF-8 is still JSON.
  const json j = parsed(status_json(StatusLevel::Error, std::string("bad \xff\xfe")));
  EXPECT_EQ(j["level"], 2);
}

TEST(FoxgloveProtocol, MessageDataLayout) {
  // spec "Message Data": opcode 0x01, uint32 LE subscription id, uint64 LE timestamp, payload.
  const std::uint8_t payload[] = {0x00, 0x01, 0x00, 0x00, 0xAB};
  const std::string frame = message_data(7, 1700000000123456789ull, payload, sizeof payload);
  const std::vector<std::uint8_t> want = {0x01, 0x07, 0x00, 0x00, 0x00, 0x15, 0xCD, 0x85, 0x3D,
                                          0xFE, 0x9C, 0x97, 0x17, 0x00, 0x01, 0x00, 0x00, 0xAB};
  ASSERT_EQ(frame.size(), kMessageDataHeaderSize + sizeof payload);
  EXPECT_EQ(std::vector<std::uint8_t>(frame.begin(), frame.end()), want);
  // Every byte of the id and time lands where the spec says.
  const std::string max = message_data(0xA1B2C3D4u, 0x0102030405060708ull, payload, 0);
  EXPECT_EQ(std::vector<std::uint8_t>(max.begin(), max.end()),
            (std::vector<std::uint8_t>{0x01, 0xD4, 0xC3, 0xB2, 0xA1, 0x08, 0x07, 0x06, 0x05, 0x04, 0x03, 0x02, 0x01}));
}

TEST(FoxgloveProtocol, ParsesSubscribeAndUnsubscribe) {
  const auto sub = parse_client_text(
      R"({"op":"subscribe","subscriptions":[{"id":0,"channelId":3},{"id":4294967295,"channelId":0}]})");
  ASSERT_TRUE(std::holds_alternative<SubscribeRequest>(sub));
  const auto& s = std::get<SubscribeRequest>(sub).subscriptions;
  ASSERT_EQ(s.size(), 2u);
  EXPECT_EQ(s[0].id, 0u);
  EXPECT_EQ(s[0].channel, 3u);
  EXPECT_EQ(s[1].id, 4294967295u);
  const auto unsub = parse_client_text(R"({"op":"unsubscribe","subscriptionIds":[2,9]})");
  ASSERT_TRUE(std::holds_alternative<UnsubscribeRequest>(unsub));
  EXPECT_EQ(std::get<UnsubscribeRequest>(unsub).ids, (std::vector<std::uint32_t>{2, 9}));
}

// Every malformed or unsupported client message becomes a BadRequest saying what is wrong.
TEST(FoxgloveProtocol, RefusesMalformedRequestsWithAReason) {
  struct Case {
    const char* text;
    const char* says;
  };
  const Case cases[] = {
      {"", "not JSON"},
      {"{\"op\":", "not JSON"},
      {"\xff\xfe", "not JSON"},
      {"[1,2]", "must be a JSON object"},
      {"{\"subscriptions\":[]}", "without a string \"op\""},
      {"{\"op\":7}", "without a string \"op\""},
      {"{\"op\":\"fly\"}", "unknown op \"fly\""},
      {"{\"op\":\"advertise\",\"channels\":[]}", "op \"advertise\" is not supported"},
      {"{\"op\":\"getParameters\",\"parameterNames\":[]}", "op \"getParameters\" is not supported"},
      {"{\"op\":\"subscribe\"}", "\"subscriptions\" must be an array"},
      {"{\"op\":\"subscribe\",\"subscriptions\":{}}", "\"subscriptions\" must be an array"},
      {"{\"op\":\"subscribe\",\"subscriptions\":[3]}", "subscriptions[0] must be an object"},
      {"{\"op\":\"subscribe\",\"subscriptions\":[{\"channelId\":1}]}", "subscriptions[0].id is missing"},
      {"{\"op\":\"subscribe\",\"subscriptions\":[{\"id\":1,\"channelId\":1},{\"id\":2}]}",
       "subscriptions[1].channelId is missing"},
      {"{\"op\":\"subscribe\",\"subscriptions\":[{\"id\":-1,\"channelId\":1}]}",
       ".id must be an integer 0..4294967295, not -1"},
      {"{\"op\":\"subscribe\",\"subscriptions\":[{\"id\":1.5,\"channelId\":1}]}", ".id must be an integer"},
      {"{\"op\":\"subscribe\",\"subscriptions\":[{\"id\":4294967296,\"channelId\":1}]}", ".id must be an integer"},
      {"{\"op\":\"subscribe\",\"subscriptions\":[{\"id\":\"1\",\"channelId\":1}]}", "not \"1\""},
      {"{\"op\":\"unsubscribe\"}", "\"subscriptionIds\" must be an array"},
      {"{\"op\":\"unsubscribe\",\"subscriptionIds\":[1,null]}", "subscriptionIds[1] must be an integer"},
  };
  for (const auto& c : cases) {
    const auto r = parse_client_text(c.text);
    ASSERT_TRUE(std::holds_alternative<BadRequest>(r)) << c.text;
    EXPECT_NE(std::get<BadRequest>(r).why.find(c.says), std::string::npos)
        << c.text << " -> " << std::get<BadRequest>(r).why;
  }
}

TEST(FoxgloveProtocol, QuotesOnlyTheStartOfALongMessage) {
  const std::string junk(10000, 'x');
  const auto why = std::get<BadRequest>(parse_client_text(junk)).why;
  EXPECT_LT(why.size(), 100u) << why;
  EXPECT_NE(why.find("..."), std::string::npos);
}

TEST(FoxgloveProtocol, BinaryClientMessagesAreRefused) {
  const std::uint8_t publish[] = {0x01, 0x00, 0x00, 0x00, 0x00};
  EXPECT_NE(parse_client_binary(publish, sizeof publish).why.find("opcode 1 is not supported"), std::string::npos);
  EXPECT_NE(parse_client_binary(publish, 0).why.find("empty"), std::string::npos);
}

TEST(ClientSubscriptions, SubscribeMapsChannelsToTheClientsIds) {
  ClientSubscriptions s(3);
  EXPECT_TRUE(
      s.on_text(R"({"op":"subscribe","subscriptions":[{"id":10,"channelId":2},{"id":11,"channelId":0}]})").empty());
  EXPECT_EQ(s.subscription(2), 10u);
  EXPECT_EQ(s.subscription(0), 11u);
  EXPECT_FALSE(s.subscription(1));
  EXPECT_FALSE(s.subscription(99));
  EXPECT_EQ(s.count(), 2u);
  EXPECT_TRUE(s.on_text(R"({"op":"unsubscribe","subscriptionIds":[10]})").empty());
  EXPECT_FALSE(s.subscription(2));
  EXPECT_EQ(s.subscription(0), 11u);
  // The id is free again, and the channel too.
  EXPECT_TRUE(s.on_text(R"({"op":"subscribe","subscriptions":[{"id":10,"channelId":1}]})").empty());
  EXPECT_EQ(s.subscription(1), 10u);
}

TEST(ClientSubscriptions, AnswersEachRefusedPartWithAStatus) {
  ClientSubscriptions s(2);
  ASSERT_TRUE(s.on_text(R"({"op":"subscribe","subscriptions":[{"id":1,"channelId":0}]})").empty());

  json j = only_status(s.on_text(R"({"op":"subscribe","subscriptions":[{"id":1,"channelId":1}]})"));
  EXPECT_EQ(j["level"], 2);
  EXPECT_EQ(j["message"], "subscription id 1 is already used; subscription ignored");
  EXPECT_FALSE(s.subscription(1));

  j = only_status(s.on_text(R"({"op":"subscribe","subscriptions":[{"id":2,"channelId":7}]})"));
  EXPECT_EQ(j["level"], 2);
  EXPECT_EQ(j["message"], "channel 7 was not advertised; subscription ignored");

  j = only_status(s.on_text(R"({"op":"subscribe","subscriptions":[{"id":3,"channelId":0}]})"));
  EXPECT_EQ(j["level"], 1);
  EXPECT_EQ(j["message"], "already subscribed to channel 0 (subscription 1); subscription ignored");
  EXPECT_EQ(s.subscription(0), 1u);

  j = only_status(s.on_text(R"({"op":"unsubscribe","subscriptionIds":[42]})"));
  EXPECT_EQ(j["level"], 1);
  EXPECT_EQ(j["message"], "no subscription 42 to end");

  // Good parts of a request are kept beside refused ones.
  const auto replies =
      s.on_text(R"({"op":"subscribe","subscriptions":[{"id":5,"channelId":9},{"id":6,"channelId":1}]})");
  EXPECT_EQ(replies.size(), 1u);
  EXPECT_EQ(s.subscription(1), 6u);
  EXPECT_EQ(s.count(), 2u);
}

TEST(ClientSubscriptions, MalformedMessagesChangeNothingAndAreAnsweredWithAnError) {
  ClientSubscriptions s(2);
  ASSERT_TRUE(s.on_text(R"({"op":"subscribe","subscriptions":[{"id":1,"channelId":0}]})").empty());
  for (const char* text :
       {"nonsense", "{\"op\":\"subscribe\",\"subscriptions\":[{\"id\":2,\"channelId\":1},{\"id\":-3}]}",
        "{\"op\":\"unsubscribe\",\"subscriptionIds\":[1,\"x\"]}", "{\"op\":\"setParameters\"}"}) {
    const json j = only_status(s.on_text(text));
    EXPECT_EQ(j["level"], 2) << text;
    EXPECT_FALSE(j["message"].get<std::string>().empty());
  }
  EXPECT_EQ(s.subscription(0), 1u);  // the unsubscribe with a bad id was refused whole
  EXPECT_FALSE(s.subscription(1));   // so was the subscribe with a bad part
  const std::uint8_t data[] = {0x02, 0x00};
  EXPECT_EQ(only_status(s.on_binary(data, sizeof data))["level"], 2);
}

}  // namespace
}  // namespace pmu::tools::foxglove
