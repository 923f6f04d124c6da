// What a pmuctl call sends `pmuctl agent` (tools/pmuctl/agent/agent_request.hpp): a request
// survives its encoding, its caller's deadline and lane included, and every malformed one is
// refused whole with a reason, never half-read; replies likewise; and the socket's default
// path.
#include <gtest/gtest.h>
#include <stdlib.h>
#include <sys/socket.h>
#include <unistd.h>

#include <string>

#include "pmuctl/agent/agent_request.hpp"
#include "pmuctl/agent/unix_socket.hpp"

namespace {

using pmu::tools::AgentReply;
using pmu::tools::AgentRequest;

std::string nul(std::initializer_list<std::string> parts) {
  std::string s;
  for (const auto& p : parts) s += p + std::string(1, '\0');
  return s;
}

TEST(AgentRequest, SurvivesItsEncoding) {
  AgentRequest r;
  r.deadline_ns = 1790000000123456789ull;
  r.engine_stop = true;
  r.directory = "/home/op/fleet";
  r.environment = {{"PMU_VEHICLE", "uav1"}, {"PMU_DISCOVERY_SERVER", "10.0.0.1"}};
  r.arguments = {"--json", "config", "set", "payload_voltage", "13.5", ""};  // an empty argument too
  std::string error;
  const auto back = pmu::tools::decode_request(pmu::tools::encode_request(r), error);
  ASSERT_TRUE(back) << error;
  EXPECT_EQ(back->deadline_ns, r.deadline_ns);
  EXPECT_TRUE(back->engine_stop);
  EXPECT_EQ(back->directory, r.directory);
  EXPECT_EQ(back->environment, r.environment);
  EXPECT_EQ(back->arguments, r.arguments);
}

struct Bad {
  const char* what;
  std::string bytes;
  const char* error;
};

TEST(AgentRequest, EveryMalformedRequestIsRefusedWithItsReason) {
  const std::string not_ours = "not a pmuctl agent request (it does not begin with \"pmuctl-agent-2\")";
  const Bad cases[] = {
      {"empty", "", not_ours.c_str()},
      {"another program", nul({"GET / HTTP/1.1", "/", "0"}), not_ours.c_str()},
      {"an older version, without deadline nor lane", nul({"pmuctl-agent-1", "/", "0", "list"}), not_ours.c_str()},
      {"no terminating NUL", nul({"pmuctl-agent-2", "1", "call", "/", "0"}) + "list",
       "a request's last string has no terminating NUL"},
      {"a deadline that is not a number", nul({"pmuctl-agent-2", "soon", "call", "/", "0", "list"}),
       "the deadline 'soon' is not a time in ns since the epoch"},
      {"no deadline", nul({"pmuctl-agent-2", "0", "call", "/", "0", "list"}),
       "the deadline '0' is not a time in ns since the epoch"},
      {"an unknown lane", nul({"pmuctl-agent-2", "1", "fast", "/", "0", "list"}),
       "the lane 'fast' is neither stop nor call"},
      {"a relative directory", nul({"pmuctl-agent-2", "1", "call", "fleet", "0", "list"}),
       "the working directory is not an absolute path"},
      {"a count that is not a number", nul({"pmuctl-agent-2", "1", "call", "/", "x", "list"}),
       "the count of environment variables 'x' is not a number of the strings that follow"},
      {"a count beyond the strings", nul({"pmuctl-agent-2", "1", "call", "/", "2", "PMU_VEHICLE=a"}),
       "the count of environment variables '2' is not a number of the strings that follow"},
      {"a variable pmuctl does not read",
       nul({"pmuctl-agent-2", "1", "call", "/", "1", "LD_PRELOAD=/tmp/x.so", "list"}),
       "environment entry 1 is not NAME=VALUE of a variable pmuctl reads"},
      {"an entry without =", nul({"pmuctl-agent-2", "1", "call", "/", "1", "PMU_VEHICLE", "list"}),
       "environment entry 1 is not NAME=VALUE of a variable pmuctl reads"},
  };
  for (const auto& c : cases) {
    SCOPED_TRACE(c.what);
    std::string error;
    EXPECT_FALSE(pmu::tools::decode_request(c.bytes, error));
    EXPECT_EQ(error, c.error);
  }
}

TEST(AgentRequest, TooManyStringsAreRefused) {
  std::string bytes = nul({"pmuctl-agent-2", "1", "call", "/", "0"});
  for (int i = 0; i < 5000; ++i) bytes += nul({"x"});
  std::string error;
  EXPECT_FALSE(pmu::tools::decode_request(bytes, error));
  EXPECT_EQ(error, "a request of more than 4096 strings");
}

TEST(AgentReply, SurvivesItsEncodingAndAnythingElseIsNotAReply) {
  for (const AgentReply& r :
       {AgentReply{true, 0, "", false, ""}, AgentReply{true, 3, "", false, ""},
        AgentReply{false, 0, "why not", false, ""}, AgentReply{false, 0, "", true, "its wait ended first"}}) {
    const auto back = pmu::tools::decode_reply(pmu::tools::encode_reply(r));
    ASSERT_TRUE(back);
    EXPECT_EQ(back->ran, r.ran);
    EXPECT_EQ(back->status, r.status);
    EXPECT_EQ(back->declined, r.declined);
    EXPECT_EQ(back->expired, r.expired);
    EXPECT_EQ(back->why_expired, r.why_expired);
  }
  for (const char* bad : {"", "exit", "exit ", "exit -1", "exit 256", "exit 3x", "ok 0", "declined"})
    EXPECT_FALSE(pmu::tools::decode_reply(bad)) << bad;
}

TEST(AgentSocket, DefaultsToTheUsersRuntimeDirectoryElseRun) {
  const char* saved_socket = std::getenv("PMU_AGENT_SOCKET");
  const char* saved_run = std::getenv("XDG_RUNTIME_DIR");
  const std::string keep_socket = saved_socket ? saved_socket : "", keep_run = saved_run ? saved_run : "";
  ::unsetenv("PMU_AGENT_SOCKET");
  ::setenv("XDG_RUNTIME_DIR", "/run/user/1000", 1);
  EXPECT_EQ(pmu::tools::agent_socket_path(7), "/run/user/1000/pmu-dds/agent-7.sock");
  ::unsetenv("XDG_RUNTIME_DIR");
  EXPECT_EQ(pmu::tools::agent_socket_path(0), "/run/pmu-dds/agent-0.sock");
  ::setenv("PMU_AGENT_SOCKET", "/tmp/a.sock", 1);
  EXPECT_EQ(pmu::tools::agent_socket_path(0), "/tmp/a.sock");
  if (saved_socket)
    ::setenv("PMU_AGENT_SOCKET", keep_socket.c_str(), 1);
  else
    ::unsetenv("PMU_AGENT_SOCKET");
  if (saved_run) ::setenv("XDG_RUNTIME_DIR", keep_run.c_str(), 1);
}

TEST(UnixSocket, AMessageAndItsDescriptorsArriveTogether) {
  int pair[2];
  ASSERT_EQ(::socketpair(AF_UNIX, SOCK_SEQPACKET, 0, pair), 0);
  pmu::tools::UniqueFd a(pair[0]), b(pair[1]);
  int pipe_fds[2];
  ASSERT_EQ(::pipe(pipe_fds), 0);
  pmu::tools::UniqueFd read_end(pipe_fds[0]), write_end(pipe_fds[1]);
  ASSERT_TRUE(pmu::tools::send_with_fds(a.get(), "hello", {write_end.get()}));
  std::string got;
  std::vector<pmu::tools::UniqueFd> fds;
  ASSERT_TRUE(pmu::tools::receive(b.get(), got, &fds));
  EXPECT_EQ(got, "hello");
  ASSERT_EQ(fds.size(), 1u);
  // The received descriptor is the pipe's write end: what goes in comes out of the read end.
  ASSERT_EQ(::write(fds[0].get(), "x", 1), 1);
  char c = 0;
  ASSERT_EQ(::read(read_end.get(), &c, 1), 1);
  EXPECT_EQ(c, 'x');
  a.reset();
  EXPECT_FALSE(pmu::tools::receive(b.get(), got, &fds));  // the peer closed: no message
}

}  // namespace
