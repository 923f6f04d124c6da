#pragma once
// The Foxglove WebSocket protocol (subprotocols `foxglove.websocket.v1` and
// `foxglove.sdk.v1`, github.com/foxglove/ws-protocol docs/spec.md) as far as `pmuctl serve`
// speaks it: the server's JSON messages, binary MessageData and Time frames, the choice of
// subprotocol, and the client's subscribe and unsubscribe requests turned into typed values. Pure: no sockets, threads or clock, so every
// byte is checked by tests/pmuctl/foxglove_protocol_test.cpp.
//
//   message_data(7, 1700000000123456789, {0x00,0x01,0x00,0x00})
//     -> 01 | 07 00 00 00 | 15 CD 85 3D FE 9C 97 17 | 00 01 00 00
//        op   subscription   timestamp (ns, u64 LE)   payload (the CDR bytes)
//   time_message(1700000000123456789)
//     -> 02 | 15 CD 85 3D FE 9C 97 17      (capability `time`: the server's clock, ns)
//   choose_subprotocol({"foxglove.sdk.v1", "foxglove.websocket.v1"}) -> "foxglove.sdk.v1"
//   parse_client_text(R"({"op":"subscribe","subscriptions":[{"id":0,"channelId":3}]})")
//     -> SubscribeRequest{{{0, 3}}}
//   parse_client_text("{\"op\":\"fly\"}") -> BadRequest{"unknown op \"fly\" ..."}
//
// Error handling: whatever a client sends becomes a request or a BadRequest that says what
// is wrong; nothing throws (nlohmann's parser runs with exceptions off).

#include <cstdint>
#include <map>
#include <optional>
#include <string>
#include <string_view>
#include <variant>
#include <vector>

namespace pmu::tools::foxglove {

// What the spec names the protocol, and what the Foxglove SDK (foxglove_bridge 3) names the
// same messages; this server speaks the part both share, so it accepts either.
inline constexpr std::string_view kSubprotocol = "foxglove.websocket.v1";
inline constexpr std::string_view kSdkSubprotocol = "foxglove.sdk.v1";
inline constexpr std::string_view kSubprotocols = "foxglove.websocket.v1 or foxglove.sdk.v1";  // for messages

// The first subprotocol the client lists that this server speaks, or "" when it offers none.
std::string_view choose_subprotocol(const std::vector<std::string>& offered);

// What the server advertises: encoding `cdr`, schema encoding `omgidl` for every channel.
struct Channel {
  std::uint32_t id = 0;
  std::string topic;                            // the DDS topic name, "pmu/voltages"
  std::string schema_name;                      // the DDS type name, "pmu::v5::Voltages"
  std::string_view schema;                      // the IDL text (static storage: pmu::idl_text)
  std::string_view schema_encoding = "omgidl";  // "ros2msg" for a ROS 2 topic (pmu::ros2_msg_text)
};

enum class StatusLevel : int { Info = 0, Warning = 1, Error = 2 };

// Capabilities ["time"]: the server's clock is the source time of what it forwards (Time
// messages), and each MessageData's timestamp is the time a player shows it at.
std::string server_info_json(std::string_view name);
std::string advertise_json(const std::vector<Channel>& channels);
std::string status_json(StatusLevel level, std::string_view message);

// Binary MessageData: opcode 0x01, u32 LE subscription id, u64 LE timestamp (ns), payload.
inline constexpr std::size_t kMessageDataHeaderSize = 13;
std::string message_data(std::uint32_t subscription, std::uint64_t time_ns, const std::uint8_t* payload,
                         std::size_t size);
// Binary Time: opcode 0x02, u64 LE timestamp (ns).
std::string time_message(std::uint64_t time_ns);

// A client's request, or what is wrong with it.
struct Subscription {
  std::uint32_t id = 0;       // chosen by the client; MessageData carries it
  std::uint32_t channel = 0;  // an advertised channel id
};
struct SubscribeRequest {
  std::vector<Subscription> subscriptions;
};
struct UnsubscribeRequest {
  std::vector<std::uint32_t> ids;
};
struct BadRequest {
  std::string why;  // for a status message of level error
};
using ClientRequest = std::variant<SubscribeRequest, UnsubscribeRequest, BadRequest>;

// A text message from a client. A request in part malformed is refused whole.
ClientRequest parse_client_text(std::string_view text);
// A binary message from a client: this server has no capability that takes one.
BadRequest parse_client_binary(const std::uint8_t* data, std::size_t size);

// One client's subscriptions, by the client's ids, and the answers to its requests. At most
// one subscription per channel (as Foxglove's reference server). Channel ids are 0..count-1.
class ClientSubscriptions {
 public:
  explicit ClientSubscriptions(std::size_t channel_count) : by_channel_(channel_count) {}

  // Applies a text message; returns the status messages (JSON) to send back, none when every
  // part was accepted.
  std::vector<std::string> on_text(std::string_view text);
  std::vector<std::string> on_binary(const std::uint8_t* data, std::size_t size);

  // The client's subscription id for a channel, if it subscribed.
  std::optional<std::uint32_t> subscription(std::uint32_t channel) const {
    return channel < by_channel_.size() ? by_channel_[channel] : std::nullopt;
  }
  std::size_t count() const { return by_id_.size(); }
  // A channel advertised after the client connected: the next id.
  void add_channel() { by_channel_.emplace_back(); }

 private:
  std::map<std::uint32_t, std::uint32_t> by_id_;          // subscription id -> channel
  std::vector<std::optional<std::uint32_t>> by_channel_;  // channel -> subscription id
};

}  // namespace pmu::tools::foxglove
