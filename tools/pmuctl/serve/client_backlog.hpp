#pragma once
// The drop policy of `pmuctl serve` for one client (docs/interface.md, "Live: Foxglove
// WebSocket"): messages wait in the client's outgoing queue while its socket is full; a
// client that does not read must not make the server hold without bound, nor hold up the
// others. Pure: the server hands in the bytes its connection holds unsent.
//
//   limit 1000: offer(0, 300) send; offer(900, 200) drop, Began; offer(600, 10) drop (not
//   yet under half the limit: no flapping); offer(400, 10) send, Ended, dropped 2.
//
// A message is sent when the queue is empty (one message larger than the limit still goes)
// or the queue plus the message stay within the limit. Once dropping, sending resumes only
// when the queue is down to half the limit, so a client at the edge gets one episode (one
// stderr line, one status warning) instead of one per message.

#include <cstddef>
#include <cstdint>

namespace pmu::tools {

class ClientBacklog {
 public:
  explicit ClientBacklog(std::size_t limit_bytes) : limit_(limit_bytes) {}

  enum class Change { None, Began, Ended };  // of a dropping episode
  struct Verdict {
    bool send = true;
    Change change = Change::None;
    std::uint64_t dropped = 0;  // with Ended: the messages the episode dropped
  };

  // One message of `size` bytes for a client whose queue holds `queued` bytes.
  Verdict offer(std::size_t queued, std::size_t size) {
    Verdict v;
    const std::size_t room = dropping_ ? limit_ / 2 : limit_;
    v.send = queued == 0 || (queued <= room && size <= room - queued);
    if (!v.send) {
      ++episode_dropped_;
      ++total_dropped_;
      if (!dropping_) v.change = Change::Began;
      dropping_ = true;
    } else if (dropping_) {
      v.change = Change::Ended;
      v.dropped = episode_dropped_;
      episode_dropped_ = 0;
      dropping_ = false;
    }
    return v;
  }

  bool dropping() const { return dropping_; }
  std::uint64_t episode_dropped() const { return episode_dropped_; }  // in the current episode
  std::uint64_t total_dropped() const { return total_dropped_; }
  std::size_t limit() const { return limit_; }

 private:
  std::size_t limit_;
  bool dropping_ = false;
  std::uint64_t episode_dropped_ = 0;
  std::uint64_t total_dropped_ = 0;
};

}  // namespace pmu::tools
