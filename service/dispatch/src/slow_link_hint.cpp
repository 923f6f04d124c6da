#include "pmu/dispatch/slow_link_hint.hpp"

namespace pmu::service {

bool SlowLinkHint::resend(const std::string& sender, std::chrono::nanoseconds since_final_reply) {
  if (done_ || since_final_reply < kReplyOut) return false;
  if (first_sender_.empty()) {
    first_sender_ = sender;
    return false;
  }
  if (sender == first_sender_) return false;
  done_ = true;
  return true;
}

}  // namespace pmu::service
