#include "pmu/transport/event_loop.hpp"

#include <algorithm>
#include <cerrno>
#include <climits>
#include <system_error>
#include <utility>

#include "eventfd.hpp"

namespace pmu::transport {

EventLoop::EventLoop(const Clock& clock, std::string name)
    : clock_(clock), name_(std::move(name)), epoll_(::epoll_create1(EPOLL_CLOEXEC)) {
  if (!epoll_) throw std::system_error(errno, std::generic_category(), name_ + ": epoll_create1");
  try {
    wake_ = detail::make_eventfd();
  } catch (const std::system_error& e) {
    throw std::system_error(e.code(), name_ + ": eventfd");
  }
  // data.ptr nullptr marks the wake-up fd; every watch has its own element's address.
  struct epoll_event registration {};
  registration.events = EPOLLIN;
  registration.data.ptr = nullptr;
  if (::epoll_ctl(epoll_.get(), EPOLL_CTL_ADD, wake_.get(), &registration) != 0)
    throw std::system_error(errno, std::generic_category(), name_ + ": epoll_ctl(eventfd)");
}

EventLoop::~EventLoop() = default;

int EventLoop::watch(int fd, std::uint32_t events, FdCallback callback) {
  for (const auto& w : watches_)
    if (w.fd == fd && !w.removed) return EEXIST;
  watches_.push_back(Watch{fd, std::move(callback)});
  struct epoll_event registration {};
  registration.events = events;
  registration.data.ptr = &watches_.back();
  if (::epoll_ctl(epoll_.get(), EPOLL_CTL_ADD, fd, &registration) != 0) {
    const int error = errno;
    watches_.pop_back();
    return error;
  }
  return 0;
}

int EventLoop::unwatch(int fd) noexcept {
  const auto found =
      std::find_if(watches_.begin(), watches_.end(), [fd](const Watch& w) { return w.fd == fd && !w.removed; });
  if (found == watches_.end()) return ENOENT;
  // The fd may already be closed by a careless owner; the registration is gone then too.
  ::epoll_ctl(epoll_.get(), EPOLL_CTL_DEL, fd, nullptr);
  // While dispatching, an event collected this turn may still point at the element, and
  // the callback being run may be this one: mark it, erase it when the turn's callbacks end.
  if (dispatching_)
    found->removed = true;
  else
    watches_.erase(found);
  return 0;
}

void EventLoop::post(Work work) {
  {
    std::lock_guard<std::mutex> lock(posted_mutex_);
    posted_.push_back(std::move(work));
  }
  wake();
}

void EventLoop::post_urgent(Work work) {
  {
    std::lock_guard<std::mutex> lock(posted_mutex_);
    urgent_.push_back(std::move(work));
  }
  wake();
}

void EventLoop::wake() noexcept { detail::signal_eventfd(wake_.get()); }

EventLoop::TimerId EventLoop::add_timer(TimePoint deadline, std::chrono::nanoseconds period, TimerCallback callback) {
  const TimerId id = next_timer_id_++;
  timers_.push_back(Timer{id, deadline, std::max(period, std::chrono::nanoseconds{0}), std::move(callback)});
  return id;
}

bool EventLoop::schedule(TimerId id, TimePoint deadline) noexcept {
  for (auto& t : timers_) {
    if (t.id != id || t.removed) continue;
    t.deadline = deadline;
    t.armed = true;
    return true;
  }
  return false;
}

bool EventLoop::disarm(TimerId id) noexcept {
  for (auto& t : timers_) {
    if (t.id != id || t.removed) continue;
    t.armed = false;
    return true;
  }
  return false;
}

bool EventLoop::remove_timer(TimerId id) noexcept {
  for (auto it = timers_.begin(); it != timers_.end(); ++it) {
    if (it->id != id || it->removed) continue;
    if (dispatching_)
      it->removed = true;  // its callback may be the one running
    else
      timers_.erase(it);
    return true;
  }
  return false;
}

int EventLoop::wait_ms(std::chrono::milliseconds max_wait) const noexcept {
  using std::chrono::milliseconds;
  long long wait = max_wait < milliseconds{0} ? -1 : max_wait.count();
  bool any_timer = false;
  TimePoint earliest{};
  for (const auto& t : timers_) {
    if (!t.armed || t.removed) continue;
    if (!any_timer || t.deadline < earliest) earliest = t.deadline;
    any_timer = true;
  }
  if (any_timer) {
    // Rounded up: waking a little early would only make a turn that finds nothing due.
    const auto until = std::chrono::ceil<milliseconds>(earliest - clock_.steady_now()).count();
    const long long timer_wait = std::max<long long>(until, 0);
    wait = wait < 0 ? timer_wait : std::min(wait, timer_wait);
  }
  return static_cast<int>(std::min<long long>(wait, INT_MAX));
}

std::size_t EventLoop::run_once(std::chrono::milliseconds max_wait) {
  ++turn_;
  const int ready = ::epoll_wait(epoll_.get(), ready_.data(), static_cast<int>(ready_.size()), wait_ms(max_wait));
  std::size_t called = 0;
  bool woken = false;
  dispatching_ = true;
  // Exceptions are not expected from callbacks (see the header), but the flag and the
  // deferred erasures must not be left behind if one escapes.
  struct EndDispatch {
    EventLoop& loop;
    ~EndDispatch() {
      loop.dispatching_ = false;
      loop.erase_removed();
    }
  } end_dispatch{*this};
  for (int i = 0; i < ready; ++i) woken = woken || ready_[static_cast<std::size_t>(i)].data.ptr == nullptr;
  // Reset before running the work, so a post() made by that work wakes the next turn.
  if (woken) {
    detail::clear_eventfd(wake_.get());
    called += run_urgent();
  }
  for (int i = 0; i < ready; ++i) {
    const struct epoll_event& event = ready_[static_cast<std::size_t>(i)];
    if (event.data.ptr == nullptr) continue;
    Watch& w = *static_cast<Watch*>(event.data.ptr);
    if (w.removed || !w.callback) continue;
    w.callback(event.events);
    ++called;
  }
  if (woken) called += run_posted();
  called += fire_due_timers();
  return called;
}

std::size_t EventLoop::run_urgent() {
  {
    std::lock_guard<std::mutex> lock(posted_mutex_);
    if (urgent_.empty()) return 0;
    running_.swap(urgent_);
  }
  const std::size_t count = running_.size();
  for (auto& work : running_) work();
  running_.clear();
  return count;
}

std::size_t EventLoop::run_posted() {
  // Urgent work posted since step 2 (by an fd callback) still goes first.
  const std::size_t urgent = run_urgent();
  {
    std::lock_guard<std::mutex> lock(posted_mutex_);
    running_.swap(posted_);
  }
  const std::size_t count = running_.size();
  for (auto& work : running_) work();
  running_.clear();
  return urgent + count;
}

std::size_t EventLoop::fire_due_timers() {
  if (timers_.empty()) return 0;
  const TimePoint now = clock_.steady_now();
  std::size_t fired = 0;
  for (;;) {
    // The earliest due timer not yet fired this turn; the list keeps the order added, so
    // the first of equal deadlines wins.
    Timer* next = nullptr;
    for (auto& t : timers_) {
      if (!t.armed || t.removed || t.fired_turn == turn_ || t.deadline > now) continue;
      if (next == nullptr || t.deadline < next->deadline) next = &t;
    }
    if (next == nullptr) return fired;
    next->fired_turn = turn_;
    // Re-armed (or disarmed) before the callback runs, so the callback may re-arm it,
    // disarm it or remove it and have the last word.
    if (next->period.count() == 0) {
      next->armed = false;
    } else {
      next->deadline += next->period;
      if (next->deadline <= now) next->deadline = now + next->period;
    }
    if (next->callback) next->callback(now);
    ++fired;
  }
}

void EventLoop::erase_removed() noexcept {
  watches_.remove_if([](const Watch& w) { return w.removed; });
  timers_.remove_if([](const Timer& t) { return t.removed; });
}

void EventLoop::run(std::chrono::milliseconds max_wait, const std::function<void()>& after_turn) {
  while (!stop_.exchange(false, std::memory_order_acq_rel)) {
    run_once(max_wait);
    if (after_turn) after_turn();
  }
}

void EventLoop::stop() noexcept {
  stop_.store(true, std::memory_order_release);
  wake();
}

}  // namespace pmu::transport
