#pragma once
// The Foxglove WebSocket protocol (subprotocol `foxglove.websocket.v1`,
// github.com/foxglove/ws-protocol docs/spec.md) as far as `pmuctl serve` speaks it: the
// server's JSON messages and binary MessageData frames, and the client's subscribe and
// unsubscribe requests turned into typed values. Pure: no sockets, threads or clock, so every
// byte is checked by tests/unit/foxglove_protocol_test.cpp.
//
//   message_data(7, 1700000000123456789, {0x00,0x01,0x00,0x00})
//     -> 01 | 07 00 00 00 | 15 CD 85 3D FE 9C 97 17 | 00 01 00 00
//        op   subscription   timestamp (ns, u64 LE)   payload (the CDR bytes)
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

inline constexpr std::string_view kSubprotocol = "foxglove.websocket.v1";

// What the server advertises: encoding `cdr`, schema encoding `omgidl` for every channel.
struct Channel {
  std::uint32_t id = 0;
  std::string topic;        // the DDS topic name, "pmu/voltages"
  std::string schema_name;  // the DDS type name, "pmu::v5::Voltages"
  std::string_view schema;  // the IDL text (static storage: pmu::idl_text)
};

enum class StatusLevel : int { Info = 0, Warning = 1, Error = 2 };

std::string server_info_json(std::string_view name);
std::string advertise_json(const std::vector<Channel>& channels);
std::string status_json(StatusLevel level, std::string_view message);

// Binary MessageData: opcode 0x01, u32 LE subscription id, u64 LE timestamp (ns), payload.
inline constexpr std::size_t kMessageDataHeaderSize = 13;
std::string message_data(std::uint32_t subscription, std::uint64_t time_ns, const std::uint8_t* payload,
                         std::size_t size);

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

 private:
  std::map<std::uint32_t, std::uint32_t> by_id_;             // subscription id -> channel
  std::vector<std::optional<std::uint32_t>> by_channel_;     // channel -> subscription id
};

}  // namespace pmu::tools::foxglove
