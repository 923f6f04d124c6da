// The runner of command plans (command_plan.hpp): one Run per command, owned by the
// callbacks of its pending step. Each step's callback holds a shared_ptr to the Run and
// submits the next step, so the Run lives exactly as long as a step is outstanding and
// nothing refers to itself.
#include <memory>
#include <string>
#include <vector>

#include "pmu/codec/encode.hpp"
#include "pmu/dispatch/command_plan.hpp"
#include "pmu/dispatch/command_reply.hpp"

namespace pmu::service {
namespace {

class Run : public std::enable_shared_from_this<Run> {
 public:
  Run(DeviceSession& session, const CommandRequest& request, CommandPlan plan, const Timeouts& timeouts, ReplyFn reply)
      : session_(session),
        request_(request),
        plan_(std::move(plan)),
        retries_(timeouts.retries),
        reply_(std::move(reply)) {}

  // Step 0: the command's own frame.
  void start(SteadyTime now) {
    if (plan_.urgent) return send_urgent(now);
    if (plan_.alias) session_.set_alias(plan_.alias);
    Request r;
    r.frame = plan_.frame;
    r.reply = plan_.answer;
    r.retries = plan_.idempotent ? retries_ : 0;
    if (!plan_.urgent) r.expires = request_.expires;
    r.done = [self = shared_from_this()](const RequestOutcome& o) { self->on_command(o); };
    session_.submit(std::move(r), now);
  }

 private:
  // An engine stop: out at once, to where the unit is now (DeviceSession::send_urgent;
  // docs/safety.md H4). Nothing answers it, so sending it is the whole command.
  void send_urgent(SteadyTime now) {
    const auto sent = session_.send_urgent(plan_.frame, now);
    RequestOutcome o;
    o.status = sent.result.ok() ? RequestStatus::Sent : RequestStatus::SendFailed;
    o.send = sent.result;
    if (!succeeded(o, plan_.what)) return;
    Verdict v = plan_.check(nullptr);
    v.reason += where(sent.addresses);
    conclude(std::move(v));
  }

  // Where an urgent frame went, when that is not simply the address the request named.
  std::string where(const std::vector<std::uint16_t>& addresses) const {
    if (addresses.empty() || (addresses.size() == 1 && addresses[0] == request_.address)) return {};
    if (addresses.size() == 1)
      return " to address " + std::to_string(addresses[0]) + ", where the unit is now (it was " +
             std::to_string(request_.address) + ")";
    std::string list;
    for (std::size_t i = 0; i < addresses.size(); ++i)
      list += (i == 0 ? "" : i + 1 == addresses.size() ? " and " : ", ") + std::to_string(addresses[i]);
    return " to addresses " + list + ": its CAN address is being changed";
  }

  void on_command(const RequestOutcome& o) {
    if (!succeeded(o, plan_.what)) return;
    if (plan_.read_back) return read_back(false);
    conclude(plan_.check(o.reply ? &*o.reply : nullptr));
  }

  // Steps 1 and 2: the verification get, ahead of anything queued since.
  void read_back(bool last) {
    Request r;
    // At the address the unit answers at now, unless the command itself moves it.
    const std::uint16_t address = plan_.alias ? plan_.read_back->address : session_.key().address;
    r.frame = *codec::encode_get(plan_.read_back->packet, address);
    r.reply = plan_.read_back->packet;
    r.retries = retries_;
    r.done = [self = shared_from_this(), last](const RequestOutcome& o) { self->on_read_back(o, last); };
    session_.submit_front(std::move(r), session_.now());
  }

  void on_read_back(const RequestOutcome& o, bool last) {
    if (!succeeded(o, "read-back")) return;
    Verdict v = plan_.check(&*o.reply);
    if (v.result != CommandResult::Completed && !last) return read_back(true);
    conclude(std::move(v));
  }

  // True when the step did its part; otherwise the run ends with the step's failure.
  bool succeeded(const RequestOutcome& o, const std::string& what) {
    switch (o.status) {
      case RequestStatus::Answered:
      case RequestStatus::Sent: return true;
      case RequestStatus::Expired:
        conclude({CommandResult::Rejected, "expired before it could be sent", {}, {}});
        break;
      case RequestStatus::SendFailed:
        conclude({CommandResult::Failed,
                  "bus refused the " + what + ": " + std::string(transport::to_string(o.send.status)),
                  {},
                  {}});
        break;
      case RequestStatus::Timeout:
        conclude({CommandResult::Timeout,
                  "device " + std::to_string(request_.address) + " did not answer the " + what + " after " +
                      std::to_string(retries_ + 1) + " tries",
                  {},
                  {}});
        break;
    }
    return false;
  }

  void conclude(Verdict v) {
    if (replied_) return;  // exactly one reply, whichever path ends the run
    replied_ = true;
    if (v.result == CommandResult::Completed) {
      if (plan_.on_completed) plan_.on_completed(session_);
    } else if (plan_.alias) {
      session_.set_alias(std::nullopt);
    }
    CommandReplyData d = make_reply(request_, v.result, std::move(v.reason));
    if (v.value) {
      d.has_value = true;
      d.value = *v.value;
    }
    d.value_text = std::move(v.value_text);
    reply_(d);
  }

  DeviceSession& session_;
  CommandRequest request_;
  CommandPlan plan_;
  unsigned retries_;
  ReplyFn reply_;
  bool replied_ = false;
};

}  // namespace

void run_plan(DeviceSession& session, const CommandRequest& r, CommandPlan plan, SteadyTime now,
              const Timeouts& timeouts, ReplyFn reply) {
  std::make_shared<Run>(session, r, std::move(plan), timeouts, std::move(reply))->start(now);
}

}  // namespace pmu::service
