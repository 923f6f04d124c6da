// `pmuctl serve`'s per-client drop policy (client_backlog.hpp): a client whose queue is full
// loses messages, one episode at a time, and gets them again once its queue has drained to
// half the limit.
#include <gtest/gtest.h>

#include "pmuctl/serve/client_backlog.hpp"

namespace pmu::tools {
namespace {

using Change = ClientBacklog::Change;

TEST(ClientBacklog, TheHeaderExample) {
  ClientBacklog b(1000);
  auto v = b.offer(0, 300);
  EXPECT_TRUE(v.send);
  EXPECT_EQ(v.change, Change::None);
  v = b.offer(900, 200);
  EXPECT_FALSE(v.send);
  EXPECT_EQ(v.change, Change::Began);
  EXPECT_TRUE(b.dropping());
  v = b.offer(600, 10);
  EXPECT_FALSE(v.send);
  EXPECT_EQ(v.change, Change::None);
  EXPECT_EQ(b.episode_dropped(), 2u);
  v = b.offer(400, 10);
  EXPECT_TRUE(v.send);
  EXPECT_EQ(v.change, Change::Ended);
  EXPECT_EQ(v.dropped, 2u);
  EXPECT_FALSE(b.dropping());
  EXPECT_EQ(b.episode_dropped(), 0u);
  EXPECT_EQ(b.total_dropped(), 2u);
}

TEST(ClientBacklog, SendsUpToTheLimitExactly) {
  struct Case {
    std::size_t queued, size;
    bool send;
  };
  const Case cases[] = {
      {0, 10, true},    {990, 10, true},
      {991, 10, false}, {1000, 0, true},
      {1000, 1, false}, {0, 5000, true},  // larger than the limit, but nothing waits: it goes
      {1, 5000, false}, {static_cast<std::size_t>(-1), 1, false},
  };
  for (const auto& c : cases) {
    ClientBacklog b(1000);
    EXPECT_EQ(b.offer(c.queued, c.size).send, c.send) << c.queued << " + " << c.size;
  }
}

TEST(ClientBacklog, OneEpisodeForAClientThatNeverReads) {
  ClientBacklog b(1000);
  std::size_t queued = 0;
  int began = 0, sent = 0;
  for (int i = 0; i < 1000; ++i) {
    const auto v = b.offer(queued, 100);
    if (v.change == Change::Began) ++began;
    EXPECT_NE(v.change, Change::Ended);
    if (v.send) {
      queued += 100;
      ++sent;
    }
  }
  EXPECT_EQ(sent, 10);
  EXPECT_EQ(began, 1);
  EXPECT_EQ(b.episode_dropped(), 990u);
  EXPECT_EQ(b.total_dropped(), 990u);
}

TEST(ClientBacklog, AClientAtTheEdgeDoesNotFlap) {
  // Drains 90 bytes for every 100 offered: without hysteresis every other message would
  // begin and end an episode.
  ClientBacklog b(1000);
  std::size_t queued = 0;
  int episodes = 0;
  for (int i = 0; i < 200; ++i) {
    const auto v = b.offer(queued, 100);
    if (v.change == Change::Began) ++episodes;
    if (v.send) queued += 100;
    queued = queued > 90 ? queued - 90 : 0;
  }
  EXPECT_LE(episodes, 4);
  EXPECT_GT(b.total_dropped(), 0u);
}

TEST(ClientBacklog, EpisodesCountSeparately) {
  ClientBacklog b(100);
  b.offer(100, 10);
  b.offer(100, 10);
  auto v = b.offer(0, 10);
  EXPECT_EQ(v.change, Change::Ended);
  EXPECT_EQ(v.dropped, 2u);
  v = b.offer(100, 10);
  EXPECT_EQ(v.change, Change::Began);
  v = b.offer(40, 10);
  EXPECT_EQ(v.change, Change::Ended);
  EXPECT_EQ(v.dropped, 1u);
  EXPECT_EQ(b.total_dropped(), 3u);
}

}  // namespace
}  // namespace pmu::tools
