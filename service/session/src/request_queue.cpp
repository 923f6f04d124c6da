#include "pmu/session/request_queue.hpp"

#include "pmu/codec/ids.hpp"

namespace pmu::service {

RequestQueue::RequestQueue(SendFn send, std::chrono::milliseconds reply_timeout)
    : send_(std::move(send)), reply_timeout_(reply_timeout) {}

void RequestQueue::push_back(Request request, SteadyTime now) {
  queue_.push_back(std::move(request));
  pump(now);
}

void RequestQueue::push_front(Request request, SteadyTime now) {
  queue_.push_front(std::move(request));
  pump(now);
}

void RequestQueue::append(std::vector<Request> requests, SteadyTime now) {
  for (auto& r : requests) queue_.push_back(std::move(r));
  pump(now);
}

void RequestQueue::pump(SteadyTime now) {
  if (pumping_) return;
  pumping_ = true;
  while (!in_flight_ && !queue_.empty()) {
    in_flight_ = std::move(queue_.front());
    queue_.pop_front();
    attempts_ = 1;
    if (in_flight_->expires && now > *in_flight_->expires) {
      RequestOutcome o;
      o.status = RequestStatus::Expired;
      end(std::move(o));
      continue;
    }
    const auto sent = send_(in_flight_->frame);
    if (sent.ok() && in_flight_->reply) {
      deadline_ = now + reply_timeout_;
      break;
    }
    RequestOutcome o;
    o.status = sent.ok() ? RequestStatus::Sent : RequestStatus::SendFailed;
    o.send = sent;
    end(std::move(o));
  }
  pumping_ = false;
}

void RequestQueue::end(RequestOutcome outcome) {
  Request done = std::move(*in_flight_);
  in_flight_.reset();
  if (done.done) done.done(outcome);
}

bool RequestQueue::on_answer(const codec::PmuMessage& m, SteadyTime now) {
  if (m.request || !in_flight_ || in_flight_->reply != m.packet) return false;
  RequestOutcome o;
  o.status = RequestStatus::Answered;
  o.reply = m;
  end(std::move(o));
  pump(now);
  return true;
}

bool RequestQueue::tick(SteadyTime now) {
  if (!in_flight_ || now < deadline_) return false;
  if (attempts_ <= in_flight_->retries) {
    ++attempts_;
    (void)send_(in_flight_->frame);  // a refused resend is one more silent try
    deadline_ = now + reply_timeout_;
    return false;
  }
  RequestOutcome o;
  o.status = RequestStatus::Timeout;
  end(std::move(o));
  pump(now);
  return true;
}

void RequestQueue::drop(int tag) {
  for (auto it = queue_.begin(); it != queue_.end();) it = it->tag == tag ? queue_.erase(it) : std::next(it);
}

void RequestQueue::readdress(std::uint16_t from, std::uint16_t to) {
  const auto move = [from, to](Request& r) {
    const auto id = codec::parse_id(r.frame.id, r.frame.extended);
    if (id.id && id.id->address == from) r.frame.id = codec::make_id(id.id->packet, to);
  };
  if (in_flight_) move(*in_flight_);
  for (auto& r : queue_) move(r);
}

bool RequestQueue::waiting(int tag) const noexcept {
  for (const auto& r : queue_)
    if (r.tag == tag) return true;
  return false;
}

}  // namespace pmu::service
