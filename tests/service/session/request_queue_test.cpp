// Request correlation (request_queue.hpp) with a fake clock and a recording send function:
// matching, retries, timeouts, expiry, ordering and re-entrant submission.
#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "pmu/codec/encode.hpp"
#include "pmu/session/request_queue.hpp"

namespace pmu::service::request_queue_test {
namespace {

using namespace std::chrono_literals;
using codec::PacketId;

const SteadyTime t0 = SteadyTime{} + 1h;

struct Wire {
  std::vector<codec::CanFrame> sent;
  transport::SendStatus status = transport::SendStatus::Sent;
  RequestQueue::SendFn fn() {
    return [this](const codec::CanFrame& f) {
      transport::SendResult r;
      r.status = status;
      if (r.ok()) sent.push_back(f);
      return r;
    };
  }
};

// A get of `p` that records how it ended into `log` as "<name>:<status>".
// A request for `frame` that records how it ended into `log` as "<name>:<status>".
Request logged(const codec::Encoded& frame, std::vector<std::string>& log, const char* name) {
  EXPECT_TRUE(frame.ok()) << frame.error().describe();
  Request r;
  if (frame) r.frame = *frame;
  r.done = [&log, name](const RequestOutcome& o) {
    static const char* names[] = {"answered", "sent", "timeout", "send_failed", "expired"};
    log.push_back(std::string(name) + ":" + names[static_cast<int>(o.status)]);
  };
  return r;
}

// A get of `p`, answered by a frame of `p`.
Request get(PacketId p, std::vector<std::string>& log, unsigned retries = 0, const char* name = "get") {
  Request r = logged(codec::encode_get(p, 1), log, name);
  r.reply = p;
  r.retries = retries;
  return r;
}

// A command the device does not answer (ENGINE_START).
Request command(const char* name, std::vector<std::string>& log) {
  return logged(codec::encode_engine_start(1), log, name);
}

codec::PmuMessage data_of(PacketId p) {
  codec::PmuMessage m;
  m.packet = p;
  m.address = 1;
  m.request = false;
  return m;
}

TEST(RequestQueue, AnAnswerIsMatchedByPacketAndOnlyWhenItCarriesData) {
  struct Case {
    const char* what;
    codec::PmuMessage frame;
    bool matches;
  };
  codec::PmuMessage question = data_of(PacketId::AvionicsVoltage);
  question.request = true;
  const Case cases[] = {
      {"the same packet with data", data_of(PacketId::AvionicsVoltage), true},
      {"another packet", data_of(PacketId::ServoVoltage), false},
      {"the same packet as a zero-length get (another client's question)", question, false},
  };
  for (const auto& c : cases) {
    SCOPED_TRACE(c.what);
    Wire wire;
    std::vector<std::string> log;
    RequestQueue q(wire.fn(), 250ms);
    q.push_back(get(PacketId::AvionicsVoltage, log), t0);
    EXPECT_EQ(q.on_answer(c.frame, t0 + 1ms), c.matches);
    EXPECT_EQ(log.size(), c.matches ? 1u : 0u);
    EXPECT_EQ(q.size(), c.matches ? 0u : 1u);
  }
}

TEST(RequestQueue, OneInFlightTheRestInOrder) {
  Wire wire;
  std::vector<std::string> log;
  RequestQueue q(wire.fn(), 250ms);
  q.push_back(get(PacketId::AvionicsVoltage, log, 0, "a"), t0);
  q.push_back(get(PacketId::ServoVoltage, log, 0, "b"), t0);
  q.push_front(get(PacketId::PayloadVoltage, log, 0, "urgent"), t0);
  ASSERT_EQ(wire.sent.size(), 1u) << "the second waits for the first's answer";
  EXPECT_EQ(q.size(), 3u);
  EXPECT_TRUE(q.on_answer(data_of(PacketId::AvionicsVoltage), t0 + 1ms));
  ASSERT_EQ(wire.sent.size(), 2u);
  EXPECT_EQ(wire.sent[1].id, codec::make_id(PacketId::PayloadVoltage, 1)) << "pushed to the front";
  EXPECT_TRUE(q.on_answer(data_of(PacketId::PayloadVoltage), t0 + 2ms));
  EXPECT_TRUE(q.on_answer(data_of(PacketId::ServoVoltage), t0 + 3ms));
  EXPECT_EQ(log, (std::vector<std::string>{"a:answered", "urgent:answered", "b:answered"}));
}

TEST(RequestQueue, RetriesOnlyWhatIsSafeToRepeatThenTimesOut) {
  struct Case {
    unsigned retries;
    std::size_t frames;  // tries before Timeout
  };
  for (const Case c : {Case{0, 1}, Case{2, 3}}) {
    SCOPED_TRACE(c.retries);
    Wire wire;
    std::vector<std::string> log;
    RequestQueue q(wire.fn(), 250ms);
    q.push_back(get(PacketId::AvionicsVoltage, log, c.retries), t0);
    auto t = t0;
    bool timed_out = false;
    for (int i = 0; i < 20 && !timed_out; ++i) timed_out = q.tick(t += 100ms);
    EXPECT_TRUE(timed_out);
    EXPECT_EQ(wire.sent.size(), c.frames);
    EXPECT_EQ(log, std::vector<std::string>{"get:timeout"});
    EXPECT_FALSE(q.tick(t + 1s)) << "ends once";
  }
}

TEST(RequestQueue, AnAnswerAfterAResendStillCounts) {
  Wire wire;
  std::vector<std::string> log;
  RequestQueue q(wire.fn(), 250ms);
  q.push_back(get(PacketId::AvionicsVoltage, log, 2), t0);
  EXPECT_FALSE(q.tick(t0 + 250ms));
  EXPECT_EQ(wire.sent.size(), 2u);
  EXPECT_TRUE(q.on_answer(data_of(PacketId::AvionicsVoltage), t0 + 300ms));
  EXPECT_EQ(log, std::vector<std::string>{"get:answered"});
}

TEST(RequestQueue, WhatExpiresWhileQueuedIsNeverSent) {
  Wire wire;
  std::vector<std::string> log;
  RequestQueue q(wire.fn(), 250ms);
  q.push_back(get(PacketId::AvionicsVoltage, log, 0, "first"), t0);
  Request late = command("late", log);
  late.expires = t0 + 100ms;
  q.push_back(std::move(late), t0);
  EXPECT_TRUE(q.on_answer(data_of(PacketId::AvionicsVoltage), t0 + 200ms));
  EXPECT_EQ(wire.sent.size(), 1u);
  EXPECT_EQ(log, (std::vector<std::string>{"first:answered", "late:expired"}));
}

TEST(RequestQueue, FramesWithoutAnAnswerEndWhenSentOrRefused) {
  Wire wire;
  std::vector<std::string> log;
  RequestQueue q(wire.fn(), 250ms);
  q.push_back(command("start", log), t0);
  wire.status = transport::SendStatus::Timeout;
  q.push_back(command("refused", log), t0);
  EXPECT_EQ(log, (std::vector<std::string>{"start:sent", "refused:send_failed"}));
  EXPECT_EQ(q.size(), 0u);
}

TEST(RequestQueue, ADoneCallbackMaySubmitMoreWithoutRecursion) {
  Wire wire;
  std::vector<std::string> log;
  RequestQueue q(wire.fn(), 250ms);
  int depth = 0, deepest = 0;
  // Each command's done queues the next: ten in a chain, sent by the one running loop.
  std::function<Request(int)> chain = [&](int n) {
    Request r = command("c", log);
    r.done = [&, n](const RequestOutcome& o) {
      ++depth;
      deepest = std::max(deepest, depth);
      log.push_back("c" + std::to_string(n) + (o.status == RequestStatus::Sent ? ":sent" : ":?"));
      if (n < 9) q.push_back(chain(n + 1), t0);
      --depth;
    };
    return r;
  };
  q.push_back(chain(0), t0);
  EXPECT_EQ(wire.sent.size(), 10u);
  EXPECT_EQ(log.size(), 10u);
  EXPECT_EQ(log.back(), "c9:sent");
  EXPECT_EQ(deepest, 1) << "callbacks never nest";
}

TEST(RequestQueue, ARoundAppendedTogetherCanBeDroppedByItsFirstFailure) {
  Wire wire;
  std::vector<std::string> log;
  RequestQueue q(wire.fn(), 250ms);
  wire.status = transport::SendStatus::Down;
  std::vector<Request> round;
  for (auto p : {PacketId::Serial, PacketId::Firmware, PacketId::Outputs}) {
    Request r = get(p, log);
    r.tag = 7;
    r.done = [&](const RequestOutcome&) {
      log.push_back("failed");
      q.drop(7);
    };
    round.push_back(std::move(r));
  }
  q.append(std::move(round), t0);
  EXPECT_EQ(log, std::vector<std::string>{"failed"}) << "the rest were queued, then dropped unended";
  EXPECT_FALSE(q.waiting(7));
  EXPECT_EQ(q.size(), 0u);
}

// A unit that moved (interface.md 2.6): the request in flight is resent, and those waiting
// are sent, at its new address; a frame to another address is left as it is.
TEST(RequestQueue, ReaddressMovesTheFramesToTheAddressTheUnitLeft) {
  Wire wire;
  RequestQueue q(wire.fn(), 100ms);
  std::vector<std::string> log;
  q.push_back(get(PacketId::Status, log, 1, "in flight"), t0);
  q.push_back(get(PacketId::Serial, log, 0, "waiting"), t0);
  Request elsewhere = logged(codec::encode_get(PacketId::Firmware, 3), log, "elsewhere");
  elsewhere.reply = PacketId::Firmware;
  q.push_back(std::move(elsewhere), t0);
  q.readdress(1, 7);
  q.tick(t0 + 100ms);  // the resend of the one in flight
  q.on_answer(data_of(PacketId::Status), t0 + 110ms);
  q.on_answer(data_of(PacketId::Serial), t0 + 120ms);
  ASSERT_EQ(wire.sent.size(), 4u);
  EXPECT_EQ(wire.sent[0].id, codec::make_id(PacketId::Status, 1)) << "sent before the move";
  EXPECT_EQ(wire.sent[1].id, codec::make_id(PacketId::Status, 7));
  EXPECT_EQ(wire.sent[2].id, codec::make_id(PacketId::Serial, 7));
  EXPECT_EQ(wire.sent[3].id, codec::make_id(PacketId::Firmware, 3));
}

}  // namespace
}  // namespace pmu::service::request_queue_test
