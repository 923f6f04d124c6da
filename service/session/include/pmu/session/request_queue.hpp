#pragma once
// RequestQueue: request/response correlation for one device.
//
// The PMU's answers carry no sequence number, only the packet id they answer, so requests
// to one device are strictly serialised: one in flight, the rest waiting in order. A request
// that expects an answer is matched by the packet id of a data-carrying frame (the address
// was matched by whoever routed the frame here; a zero-length frame is a question, never an
// answer). It is resent `retries` times after `reply_timeout` of silence (only requests safe
// to repeat carry retries) and then ends in Timeout. One that waited past its expiry ends
// in Expired without being sent.
//
// Every request ends exactly once, through its `done` callback. `done` may submit more
// requests: they are queued and sent by the loop already running, never recursively.
//
// No clock of its own: time comes in through every call, so tests drive it with a fake one.
//
// Lifetime: `send` and each request's `done` may refer to the queue's owner; the queue
// calls neither once it is destroyed (a request still waiting is dropped unanswered).
// Threads: no lock: every member on its owner's thread (a DeviceSession's bus worker).

#include <chrono>
#include <cstdint>
#include <deque>
#include <functional>
#include <optional>
#include <vector>

#include "pmu/codec/decode.hpp"
#include "pmu/transport/can_bus.hpp"

namespace pmu::service {

using SteadyTime = std::chrono::steady_clock::time_point;
using WallTime = std::chrono::system_clock::time_point;

enum class RequestStatus : std::uint8_t {
  Answered,    // the device replied; `reply` holds it
  Sent,        // no reply expected (a set or command) and the bus accepted the frame
  Timeout,     // no reply after every try
  SendFailed,  // the bus refused the frame (down, gone, queue full)
  Expired,     // its expiry passed while it waited in the queue: never sent
};

struct RequestOutcome {
  RequestStatus status = RequestStatus::Sent;
  std::optional<codec::PmuMessage> reply;
  transport::SendResult send;  // the last send attempt
};

struct Request {
  codec::CanFrame frame;
  // Packet id of the expected answer; nullopt when the device sends none (sets, commands).
  std::optional<codec::PacketId> reply;
  unsigned retries = 0;  // extra tries; only for requests that are safe to repeat
  std::function<void(const RequestOutcome&)> done;
  int tag = 0;  // the session's own requests (reading, polling) are tagged to find them
  // Not sent after this time (a command that waited too long behind others is dropped).
  std::optional<std::chrono::steady_clock::time_point> expires;
};

class RequestQueue {
 public:
  using SendFn = std::function<transport::SendResult(const codec::CanFrame&)>;

  RequestQueue(SendFn send, std::chrono::milliseconds reply_timeout);

  // Queues behind (or ahead of) everything waiting and sends when nothing is in flight.
  void push_back(Request request, SteadyTime now);
  void push_front(Request request, SteadyTime now);
  // Queues all of `requests` in order before sending the first, so a first one that fails
  // at once sees the rest already queued (and may drop them).
  void append(std::vector<Request> requests, SteadyTime now);

  // A decoded frame from the device: ends the request in flight if it waits for this
  // packet and the frame carries data. True when it did.
  bool on_answer(const codec::PmuMessage& m, SteadyTime now);
  // Resends the request in flight after reply_timeout of silence, or ends it in Timeout
  // once its retries are spent. True when a request timed out.
  bool tick(SteadyTime now);

  // Forgets the waiting requests with `tag` without ending them (their round is over).
  void drop(int tag);
  // The device answers at `to` now, no longer at `from`: every request waiting or in flight
  // whose frame goes to `from` goes to `to` from its next send on. They were made for this
  // device, and a frame to the address it left reaches nothing, or another unit
  // (interface.md 2.6; docs/safety.md H4, H10).
  void readdress(std::uint16_t from, std::uint16_t to);
  // A request with `tag` waits (the one in flight does not count).
  bool waiting(int tag) const noexcept;
  // Waiting plus in flight.
  std::size_t size() const noexcept { return queue_.size() + (in_flight_ ? 1 : 0); }

 private:
  void pump(SteadyTime now);
  void end(RequestOutcome outcome);

  SendFn send_;
  std::chrono::milliseconds reply_timeout_;
  std::deque<Request> queue_;
  std::optional<Request> in_flight_;
  unsigned attempts_ = 0;
  SteadyTime deadline_{};
  bool pumping_ = false;  // a done() callback submitted more: the running loop sends it
};

}  // namespace pmu::service
