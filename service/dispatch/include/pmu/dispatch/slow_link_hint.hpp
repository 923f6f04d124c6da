#pragma once
// SlowLinkHint: when pmu-service says, once, that a link profile exists (interface.md 7.3).
//
// The evidence is a client's resend of a request whose final reply the service had published
// at least kReplyOut before the resend arrived. A client resends after 1 s without a reply
// (interface.md 2.4), so that reply was on its way for most of a second and did not arrive:
// the link has a round trip a LAN does not have, or loses packets. A client's very first
// request can also meet a reply reader that matched a moment too late (2.4), once per
// client; so the hint waits for such resends from two senders. A resend that arrives within
// kReplyOut of its reply says the service was slow, not the link, and is no evidence.
//
// Pure: no clock, no log, no DDS; the caller gives the times and logs.
// Threads: not synchronised; CommandService calls it under its mutex.

#include <chrono>
#include <string>

namespace pmu::service {

class SlowLinkHint {
 public:
  static constexpr std::chrono::milliseconds kReplyOut{300};

  // True exactly once: at the resend that makes two senders whose reply was out kReplyOut
  // or longer when they asked again. Never after quiet().
  bool resend(const std::string& sender, std::chrono::nanoseconds since_final_reply);
  // A link profile or round trip is configured: the service already knows its link.
  void quiet() noexcept { done_ = true; }

 private:
  bool done_ = false;
  std::string first_sender_;
};

}  // namespace pmu::service
