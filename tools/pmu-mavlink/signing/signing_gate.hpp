#pragma once
// What message signing (interface.md 12.6) lets through to the component, and the link state
// its own frames are signed with. Pure: the signing timestamp (pmu::mavlink::signing_timestamp
// of the injected clock) comes in as an argument.
//
// With a key, a frame ADDRESSED TO this component (its system and component id, or 0 in
// either, the broadcast) reaches no handler unless it is signed with the key, its timestamp
// is newer than the last one of its (system, component, link) stream and not more than a
// minute behind the link's: each refusal is counted by its kind. A frame addressed to
// another component is not this component's to judge (the autopilot enforces its own
// signing) and goes on unchecked, as does a message that asks nothing of anybody (HEARTBEAT,
// telemetry, STATUSTEXT). A message of unknown kind counts as addressed to this component:
// a message added to the table later is refused unsigned until it is classed here.
//
// One signing link for the component, link id 0: every endpoint gets the same signed bytes
// (one sequence, one timestamp), and the streams of the senders are one table across the
// endpoints, so a frame recorded on one endpoint and replayed on another is refused too.
//
// Without a key: nothing is signed, everything goes on. Threads: one (the program's loop).
#include <cstdint>
#include <optional>

#include "pmu/mavlink/frame.hpp"
#include "pmu/mavlink/signing.hpp"

namespace pmu::mavlink_bridge {

// The system and component a frame asks something of: the target fields of the requests
// known here (PARAM_REQUEST_READ, PARAM_REQUEST_LIST, PARAM_SET, COMMAND_LONG). nullopt for
// a message that asks nothing (HEARTBEAT, PARAM_VALUE, COMMAND_ACK, BATTERY_STATUS,
// STATUSTEXT, GENERATOR_STATUS, RELAY_STATUS) and for one of another id.
struct FrameTarget {
  std::uint8_t system = 0;
  std::uint8_t component = 0;
};
std::optional<FrameTarget> frame_target(const pmu::mavlink::Frame& frame);

// Whether `frame` asks something of component (system, component): addressed to it, or
// broadcast (0) in the system or the component field. A message of another id than those
// frame_target knows, targeted or not, is counted as addressed (refused unsigned).
bool addressed_to(const pmu::mavlink::Frame& frame, std::uint8_t system, std::uint8_t component);

class SigningGate {
 public:
  static constexpr std::uint8_t kLinkId = 0;

  // No key: signing off.
  SigningGate() = default;
  explicit SigningGate(const pmu::mavlink::SecretKey& key) : link_(std::in_place, key, kLinkId) {}

  bool enabled() const noexcept { return link_.has_value(); }

  // Whether `frame` may reach the component's handlers, this component being (system,
  // component): true without a key and for a frame not addressed to it; else the signature
  // verdict at `now` (a refusal counted by its kind).
  bool admits(const pmu::mavlink::Frame& frame, std::uint8_t system, std::uint8_t component, std::uint64_t now);

  // Whether `frame` is signed with the key, newer than its stream's last and within the
  // minute (true without a key); a refusal is counted. For a frame the component acts on
  // though it is addressed to nobody: the autopilot's HEARTBEAT that sets the system id.
  bool authentic(const pmu::mavlink::Frame& frame, std::uint64_t now);

  // The link to sign outgoing frames with (FrameWriter::encode); null without a key.
  pmu::mavlink::SigningLink* outgoing() noexcept { return link_ ? &*link_ : nullptr; }

  // Signed, accepted and refused frames by kind; null without a key.
  const pmu::mavlink::SigningCounters* counters() const noexcept { return link_ ? &link_->counters() : nullptr; }

 private:
  std::optional<pmu::mavlink::SigningLink> link_;
};

}  // namespace pmu::mavlink_bridge
