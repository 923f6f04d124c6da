#pragma once
// EventLoop: the one epoll loop of pmu-dds. The service's bus worker, the simulator's bus
// runner and the SocketCAN bus's own poll set are all built on it.
//
// Purpose
//   Waits on file descriptors, runs work posted from other threads, and fires timers kept
//   by the injected Clock, one turn at a time. A turn is:
//     1. wait until a watched fd is ready, work is posted, wake()/stop() is called, or the
//        earliest armed timer is due, but never longer than the turn's max_wait;
//     2. run the work posted urgent (post_urgent) before this turn's wait ended, in posting
//        order: ahead of the fds, which may have a flood to deliver, and of other work;
//     3. call the callback of every ready fd (in the order epoll reports them), then run
//        the work posted before this turn's wait ended (urgent first), in posting order;
//     4. fire every armed timer that is due by the clock, earliest deadline first (ties in
//        the order the timers were added).
//   run_once() is one turn (tests drive a loop with a ManualClock this way); run() turns
//   until stop().
//
// Assumptions
//   * The Clock passed in must outlive the loop, which keeps a reference. What a callback
//     refers to must outlive its registration: until unwatch() or remove_timer() returns,
//     or until the loop is destroyed. Work posted but not yet run when the loop is
//     destroyed is destroyed with it, never run.
//   * One thread runs the loop ("the loop thread"). post(), wake() and stop() may be
//     called from any thread; everything else only on the loop thread, or before the loop
//     thread starts. The loop is not re-entrant: callbacks must not call run_once()/run()
//     of the same loop (another loop is fine: SocketCanBus nests one inside a bus fd).
//   * Watched fds are level-triggered. A callback that does not consume what made its fd
//     ready is called again next turn.
//   * A watched fd must be unwatched before it is closed: epoll forgets an fd only when
//     its last duplicate is closed, and the number may be reused.
//   * Timers are read off the injected clock, not the kernel's: with a ManualClock a timer
//     fires at the first turn after the test has moved the clock past its deadline. They
//     are meant for a handful of timers per loop (a linear scan finds the earliest).
//   * fd() is the epoll fd. It is readable while a watched fd is ready or a wake-up
//     (post/wake/stop) is pending, so one loop can be watched by another. Timers do not
//     make it readable.
//
// Error handling
//   * The constructor throws std::system_error when epoll or the eventfd cannot be made
//     (start-up). Nothing throws after that: watch()/unwatch() return an errno value
//     (0 on success); a failed epoll_wait (EINTR) counts as a wait that found nothing
//     ready. Exceptions thrown by callbacks propagate to the caller of run_once()/run();
//     the callers here do not throw on their per-frame paths (docs/design.md: exceptions
//     only at start-up).
//   * Safe re-entry into the registrations: a callback may watch, unwatch, post, add or
//     remove timers and stop the loop. Once unwatch(fd) or remove_timer(id) has returned,
//     that callback is never called again, even for an event already collected this turn.
//
// Performance
//   * A turn allocates nothing: epoll results go to a fixed array, posted work is swapped
//     into a vector that keeps its capacity, timers are re-armed in place. Allocation
//     happens in watch(), add_timer() and post() (the std::function of the work).
//
// Security considerations
//   * None beyond its callers': the loop reads no data, only readiness.

#include <sys/epoll.h>

#include <array>
#include <atomic>
#include <chrono>
#include <cstddef>
#include <cstdint>
#include <functional>
#include <list>
#include <mutex>
#include <string>
#include <vector>

#include "pmu/transport/clock.hpp"
#include "pmu/transport/unique_fd.hpp"

namespace pmu::transport {

class EventLoop {
 public:
  using TimePoint = std::chrono::steady_clock::time_point;
  // `events` is the epoll mask that was reported (EPOLLIN, EPOLLOUT, EPOLLERR, EPOLLHUP...).
  using FdCallback = std::function<void(std::uint32_t events)>;
  using Work = std::function<void()>;
  // `now` is the clock reading the loop found the timer due by.
  using TimerCallback = std::function<void(TimePoint now)>;
  using TimerId = std::uint64_t;

  // What to watch for: EPOLLERR and EPOLLHUP are always reported too (epoll's rule).
  static constexpr std::uint32_t kReadable = EPOLLIN;
  static constexpr std::uint32_t kWritable = EPOLLOUT;
  // A turn's max_wait meaning "no bound": wait for an fd, a wake-up or a timer.
  static constexpr std::chrono::milliseconds kForever{-1};

  // `name` starts the messages of the exceptions ("can0: epoll_create1: ..."). Throws
  // std::system_error when epoll or the wake-up eventfd cannot be set up.
  EventLoop(const Clock& clock, std::string name);
  ~EventLoop();
  // Callbacks capture `this` of their owners and epoll holds pointers into the loop.
  EventLoop(const EventLoop&) = delete;
  EventLoop& operator=(const EventLoop&) = delete;
  EventLoop(EventLoop&&) = delete;
  EventLoop& operator=(EventLoop&&) = delete;

  int fd() const noexcept { return epoll_.get(); }

  // --- fds (loop thread) ---
  // Calls `callback` every turn `fd` is ready for `events`. An empty callback is allowed:
  // the fd then only makes fd() readable (SocketCanBus reads its socket in drain()).
  // Returns 0, EEXIST when `fd` is already watched, or epoll_ctl's errno (EBADF, EPERM
  // for a regular file, ENOMEM).
  int watch(int fd, std::uint32_t events, FdCallback callback);
  // Stops watching `fd`; its callback is not called again, even later this turn. Returns
  // 0, or ENOENT when `fd` is not watched.
  int unwatch(int fd) noexcept;

  // --- posted work and wake-ups (any thread) ---
  // Runs `work` on the loop thread in step 3 of the next turn, waking the loop if it waits.
  void post(Work work);
  // As post(), but in step 2: before the turn's fd callbacks and before all work posted
  // with post() (a command that must not wait behind others: the service's engine stop).
  void post_urgent(Work work);
  // Ends the current (or next) turn's wait without work. Nothing allocates.
  void wake() noexcept;

  // --- timers, by the injected clock (loop thread) ---
  // A timer armed for `deadline`. `period` zero: one-shot, disarmed when it fires (it stays
  // registered; schedule() arms it again). Otherwise periodic: each firing re-arms it at
  // deadline + period, or at now + period when the loop is late by a whole period (missed
  // firings are skipped, not replayed in a burst).
  TimerId add_timer(TimePoint deadline, std::chrono::nanoseconds period, TimerCallback callback);
  // Re-arms a timer for `deadline` (its period unchanged); false for an unknown id.
  bool schedule(TimerId id, TimePoint deadline) noexcept;
  // Disarms a timer without removing it; false for an unknown id.
  bool disarm(TimerId id) noexcept;
  // Removes a timer; its callback is not called again. False for an unknown id.
  bool remove_timer(TimerId id) noexcept;

  // --- turns ---
  // One turn (see the top of this file), waiting at most `max_wait` (0: only what is ready
  // now; kForever: no bound). Returns the number of callbacks called (fds, posted work,
  // timers). Loop thread.
  std::size_t run_once(std::chrono::milliseconds max_wait);
  // Turns until stop(). Each waits at most `max_wait`, and `after_turn` (if set) runs at
  // the end of each: the bus worker ticks its sessions there. The stop request is checked
  // before every turn and consumed when seen, so the turn in progress finishes, a later
  // run() runs again, and a stop() made before run() starts makes it return at once.
  void run(std::chrono::milliseconds max_wait = kForever, const std::function<void()>& after_turn = {});
  // Asks run() to return at the end of the current turn and wakes it. Any thread.
  void stop() noexcept;
  bool stop_requested() const noexcept { return stop_.load(std::memory_order_acquire); }

 private:
  struct Watch {
    int fd;
    FdCallback callback;
    bool removed = false;  // unwatched while its turn was dispatching; erased after it
  };
  struct Timer {
    TimerId id;
    TimePoint deadline;
    std::chrono::nanoseconds period;
    TimerCallback callback;
    bool armed = true;
    bool removed = false;
    std::uint64_t fired_turn = 0;  // a timer fires at most once per turn, so no callback
                                   // can keep a turn going by re-arming in the past
  };

  // The wait of this turn, in epoll_wait's milliseconds (-1: forever).
  int wait_ms(std::chrono::milliseconds max_wait) const noexcept;
  std::size_t run_posted();
  std::size_t run_urgent();
  std::size_t fire_due_timers();
  void erase_removed() noexcept;

  static constexpr std::size_t kMaxEvents = 16;  // more ready fds wait for the next turn

  const Clock& clock_;
  std::string name_;
  UniqueFd epoll_;
  UniqueFd wake_;  // eventfd: readable while a post/wake/stop waits for the loop

  // std::list: epoll's data.ptr points at the element, which must not move.
  std::list<Watch> watches_;
  std::list<Timer> timers_;  // in the order added (the tie-break)
  TimerId next_timer_id_ = 1;
  std::uint64_t turn_ = 0;
  bool dispatching_ = false;  // removals are deferred while callbacks may be running

  std::mutex posted_mutex_;
  std::vector<Work> posted_;   // guarded by posted_mutex_
  std::vector<Work> urgent_;   // guarded by posted_mutex_: post_urgent()'s
  std::vector<Work> running_;  // loop thread: this turn's posted work, capacity kept
  std::atomic<bool> stop_{false};

  std::array<struct epoll_event, kMaxEvents> ready_{};
};

}  // namespace pmu::transport
