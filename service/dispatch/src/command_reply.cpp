#include "pmu/dispatch/command_reply.hpp"

#include <utility>

namespace pmu::service {

CommandReplyData make_reply(const CommandRequest& r, CommandResult result, std::string reason) {
  CommandReplyData d;
  d.request_id = r.request_id;
  d.bus = r.bus;
  d.address = r.address;
  d.kind = r.kind();
  d.result = result;
  d.reason = std::move(reason);
  return d;
}

CommandReplyData make_reply(const CommandSample& s, CommandResult result, std::string reason) {
  CommandReplyData d;
  d.request_id = s.request_id;
  d.bus = s.bus;
  d.address = s.address;
  d.kind = s.kind < kCommandKindCount ? static_cast<CommandKind>(s.kind) : CommandKind::Get;
  d.result = result;
  d.reason = std::move(reason);
  return d;
}

}  // namespace pmu::service
