#include "pmuctl/serve/foxglove_protocol.hpp"

#include <nlohmann/json.hpp>

namespace pmu::tools::foxglove {
namespace {

using nlohmann::json;

constexpr std::size_t kQuoteMax = 40;

// JSON text of a value; bytes that are not UTF-8 become U+FFFD instead of throwing.
std::string dumped(const json& value) { return value.dump(-1, ' ', false, json::error_handler_t::replace); }

// A client's text as a JSON string, shortened, for a message that quotes it.
std::string quote_text(std::string_view text) {
  std::string s = dumped(json(std::string(text.substr(0, kQuoteMax))));
  if (text.size() > kQuoteMax) s.insert(s.size() - 1, "...");
  return s;
}

// A value the client sent, shortened.
std::string shown(const json& value) {
  std::string s = dumped(value);
  return s.size() > kQuoteMax ? s.substr(0, kQuoteMax) + "..." : s;
}

// A u32 field of an object; false with `why` set when absent or not an unsigned 32-bit integer.
bool u32_field(const json& object, const char* name, const std::string& where, std::uint32_t& out, std::string& why) {
  const auto it = object.find(name);
  if (it == object.end()) {
    why = where + "." + name + " is missing";
    return false;
  }
  // Signed JSON integers that are non-negative are parsed as unsigned by nlohmann.
  if (!it->is_number_unsigned() || it->get<std::uint64_t>() > 0xFFFFFFFFu) {
    why = where + "." + name + " must be an integer 0..4294967295, not " + shown(*it);
    return false;
  }
  out = static_cast<std::uint32_t>(it->get<std::uint64_t>());
  return true;
}

// Ops of the spec this server does not offer (its only capability is time): named, so a client
// hears that they exist but are not served, rather than "unknown".
bool is_spec_op(std::string_view op) {
  for (const char* known :
       {"advertise", "unadvertise", "getParameters", "setParameters", "subscribeParameterUpdates",
        "unsubscribeParameterUpdates", "subscribeConnectionGraph", "unsubscribeConnectionGraph", "fetchAsset"})
    if (op == known) return true;
  return false;
}

ClientRequest parse_subscribe(const json& message) {
  const auto list = message.find("subscriptions");
  if (list == message.end() || !list->is_array()) return BadRequest{"subscribe: \"subscriptions\" must be an array"};
  SubscribeRequest request;
  std::string why;
  for (std::size_t i = 0; i < list->size(); ++i) {
    const json& item = (*list)[i];
    const std::string where = "subscribe: subscriptions[" + std::to_string(i) + "]";
    if (!item.is_object()) return BadRequest{where + " must be an object {\"id\", \"channelId\"}"};
    Subscription s;
    if (!u32_field(item, "id", where, s.id, why) || !u32_field(item, "channelId", where, s.channel, why))
      return BadRequest{why};
    request.subscriptions.push_back(s);
  }
  return request;
}

ClientRequest parse_unsubscribe(const json& message) {
  const auto list = message.find("subscriptionIds");
  if (list == message.end() || !list->is_array())
    return BadRequest{"unsubscribe: \"subscriptionIds\" must be an array"};
  UnsubscribeRequest request;
  for (std::size_t i = 0; i < list->size(); ++i) {
    const json& id = (*list)[i];
    if (!id.is_number_unsigned() || id.get<std::uint64_t>() > 0xFFFFFFFFu)
      return BadRequest{"unsubscribe: subscriptionIds[" + std::to_string(i) +
                        "] must be an integer 0..4294967295, not " + shown(id)};
    request.ids.push_back(static_cast<std::uint32_t>(id.get<std::uint64_t>()));
  }
  return request;
}

void put_le(std::string& out, std::uint64_t value, int bytes) {
  for (int i = 0; i < bytes; ++i) out.push_back(static_cast<char>((value >> (8 * i)) & 0xFFu));
}

}  // namespace

std::string_view choose_subprotocol(const std::vector<std::string>& offered) {
  for (const auto& o : offered) {
    if (o == kSubprotocol) return kSubprotocol;
    if (o == kSdkSubprotocol) return kSdkSubprotocol;
  }
  return {};
}

std::string server_info_json(std::string_view name) {
  // The server only publishes: `supportedEncodings` concerns client publishing and is left out.
  return json{{"op", "serverInfo"}, {"name", std::string(name)}, {"capabilities", json::array({"time"})}}.dump();
}

std::string advertise_json(const std::vector<Channel>& channels) {
  json list = json::array();
  for (const auto& c : channels)
    list.push_back({{"id", c.id},
                    {"topic", c.topic},
                    {"encoding", "cdr"},
                    {"schemaName", c.schema_name},
                    {"schema", std::string(c.schema)},
                    {"schemaEncoding", std::string(c.schema_encoding)}});
  return json{{"op", "advertise"}, {"channels", std::move(list)}}.dump();
}

std::string status_json(StatusLevel level, std::string_view message) {
  // dumped(): a message quoting a client's bytes must not throw on invalid UTF-8.
  return dumped(json{{"op", "status"}, {"level", static_cast<int>(level)}, {"message", std::string(message)}});
}

std::string message_data(std::uint32_t subscription, std::uint64_t time_ns, const std::uint8_t* payload,
                         std::size_t size) {
  std::string out;
  out.reserve(kMessageDataHeaderSize + size);
  out.push_back('\x01');
  put_le(out, subscription, 4);
  put_le(out, time_ns, 8);
  out.append(reinterpret_cast<const char*>(payload), size);
  return out;
}

std::string time_message(std::uint64_t time_ns) {
  std::string out;
  out.reserve(9);
  out.push_back('\x02');
  put_le(out, time_ns, 8);
  return out;
}

ClientRequest parse_client_text(std::string_view text) {
  const json message = json::parse(text.begin(), text.end(), nullptr, /*allow_exceptions=*/false);
  if (message.is_discarded()) return BadRequest{"not JSON: " + quote_text(text)};
  if (!message.is_object())
    return BadRequest{"a client message must be a JSON object with \"op\", not " + quote_text(text)};
  const auto op = message.find("op");
  if (op == message.end() || !op->is_string())
    return BadRequest{"message without a string \"op\": " + quote_text(text)};
  const auto& name = op->get_ref<const std::string&>();
  if (name == "subscribe") return parse_subscribe(message);
  if (name == "unsubscribe") return parse_unsubscribe(message);
  if (is_spec_op(name))
    return BadRequest{"op \"" + name + "\" is not supported: this server only publishes (capabilities [\"time\"])"};
  return BadRequest{"unknown op " + quote_text(name) + " (this server takes subscribe and unsubscribe)"};
}

BadRequest parse_client_binary(const std::uint8_t* data, std::size_t size) {
  if (size == 0) return BadRequest{"empty binary message"};
  return BadRequest{"binary message with opcode " + std::to_string(data[0]) +
                    " is not supported: this server takes no client data (capabilities [\"time\"])"};
}

std::vector<std::string> ClientSubscriptions::on_text(std::string_view text) {
  std::vector<std::string> replies;
  const auto request = parse_client_text(text);
  if (const auto* bad = std::get_if<BadRequest>(&request)) {
    replies.push_back(status_json(StatusLevel::Error, bad->why));
  } else if (const auto* sub = std::get_if<SubscribeRequest>(&request)) {
    for (const auto& s : sub->subscriptions) {
      // The reference server's answers (FoxgloveServer.ts): each part refused alone.
      if (by_id_.count(s.id) != 0) {
        replies.push_back(status_json(StatusLevel::Error, "subscription id " + std::to_string(s.id) +
                                                              " is already used; subscription ignored"));
      } else if (s.channel >= by_channel_.size()) {
        replies.push_back(status_json(StatusLevel::Error, "channel " + std::to_string(s.channel) +
                                                              " was not advertised; subscription ignored"));
      } else if (by_channel_[s.channel]) {
        replies.push_back(status_json(StatusLevel::Warning,
                                      "already subscribed to channel " + std::to_string(s.channel) + " (subscription " +
                                          std::to_string(*by_channel_[s.channel]) + "); subscription ignored"));
      } else {
        by_id_[s.id] = s.channel;
        by_channel_[s.channel] = s.id;
      }
    }
  } else {
    for (const auto id : std::get<UnsubscribeRequest>(request).ids) {
      const auto it = by_id_.find(id);
      if (it == by_id_.end()) {
        replies.push_back(status_json(StatusLevel::Warning, "no subscription " + std::to_string(id) + " to end"));
        continue;
      }
      by_channel_[it->second].reset();
      by_id_.erase(it);
    }
  }
  return replies;
}

std::vector<std::string> ClientSubscriptions::on_binary(const std::uint8_t* data, std::size_t size) {
  return {status_json(StatusLevel::Error, parse_client_binary(data, size).why)};
}

}  // namespace pmu::tools::foxglove
