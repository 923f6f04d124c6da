// pmuctl's discovery, interface and link options and their environment variables (interface.md
// sections 7.2, 7.3): every bad value is refused before any DDS participant exists, with exit
// status 2 and a message naming the option or the variable. (That options win over the
// variables needs a participant: tests/integration/discovery_test.cpp, since Fast DDS 2.9.1
// trips AddressSanitizer, under which this label runs too.)
#include <gtest/gtest.h>

#include <string>

#include "support/process.hpp"

namespace {

struct BadCase {
  const char* command;  // environment assignments and pmuctl's arguments
  const char* message;  // stderr, whole
};

// `env -u` first: a variable exported where the tests run must not change them.
std::string pmuctl(const std::string& command) {
  const auto at = command.find("pmuctl");
  return "env -u PMU_DDS_PEERS -u PMU_DISCOVERY_SERVER -u PMU_DDS_INTERFACES -u PMU_LINK " + command.substr(0, at) +
         PMUCTL_PATH + command.substr(at + 6) + " 2>&1 >/dev/null";
}

const BadCase kBad[] = {
    {"pmuctl --peer 10.0.0.1:0 list", "pmuctl: --peer '10.0.0.1:0': port 0 out of range 1..65535\n"},
    {"pmuctl --peer 10.0.0.1:70000 list", "pmuctl: --peer '10.0.0.1:70000': port 70000 out of range 1..65535\n"},
    {"pmuctl --peer 10.0.0.1 --peer 10.0.0.1 list", "pmuctl: --peer '10.0.0.1' given twice\n"},
    {"pmuctl --peer bad_host list",
     "pmuctl: --peer 'bad_host': 'bad_host' is not an IPv4 address or a host name (letters, digits, '-' and '.')\n"},
    {"pmuctl --peer nowhere.invalid list",
     "pmuctl: --peer: peer 'nowhere.invalid': host name 'nowhere.invalid' does not resolve to an IPv4 address\n"},
    {"PMU_DDS_PEERS=10.0.0.1,,10.0.0.2 pmuctl list", "pmuctl: PMU_DDS_PEERS '': empty address\n"},
    {"PMU_DDS_PEERS=10.0.0.256 pmuctl list",
     "pmuctl: PMU_DDS_PEERS '10.0.0.256': '10.0.0.256' is not an IPv4 address (four numbers 0..255: 192.168.10.2)\n"},
    {"pmuctl --peer 10.0.0.1 --discovery-server 10.0.0.2 list",
     "pmuctl: --peer (unicast discovery) and --discovery-server exclude each other\n"},
    {"PMU_DDS_PEERS=10.0.0.1 PMU_DISCOVERY_SERVER=10.0.0.2 pmuctl list",
     "pmuctl: PMU_DDS_PEERS (unicast discovery) and PMU_DISCOVERY_SERVER are both set: unset one, or give --peer or "
     "--discovery-server\n"},
    {"pmuctl --discovery-server 10.0.0.1,10.0.0.300:11811 list",
     "pmuctl: --discovery-server '10.0.0.300:11811': '10.0.0.300' is not an IPv4 address (four numbers 0..255: "
     "192.168.10.2)\n"},
    {"pmuctl --discovery-server 10.0.0.1:11811,10.0.0.1:11811 list",
     "pmuctl: --discovery-server '10.0.0.1:11811' given twice\n"},
    {"PMU_DISCOVERY_SERVER='[::1]:11811' pmuctl list",
     "pmuctl: PMU_DISCOVERY_SERVER '[::1]:11811': IPv6 is not supported (Fast DDS's UDPv4 transport carries DDS "
     "here): give an IPv4 address or a host name\n"},
    {"PMU_DISCOVERY_SERVER=10.0.0.1:x pmuctl list",
     "pmuctl: PMU_DISCOVERY_SERVER '10.0.0.1:x': port 'x' is not a number\n"},
    {"pmuctl --discovery-server , list",
     "pmuctl: --discovery-server names no server (an empty entry only leaves its id unused)\n"},
    {"PMU_DISCOVERY_SERVER=' , ' pmuctl list",
     "pmuctl: PMU_DISCOVERY_SERVER names no server (an empty entry only leaves its id unused)\n"},
    {"pmuctl --interface eth1/x list",
     "pmuctl: --interface 'eth1/x': 'eth1/x' is not an interface name (1..15 characters, no '/', ':' or space) or an "
     "IPv4 address\n"},
    {"PMU_DDS_INTERFACES=lo,lo pmuctl list", "pmuctl: PMU_DDS_INTERFACES 'lo' given twice\n"},
    {"PMU_DDS_INTERFACES=192.168.1 pmuctl list",
     "pmuctl: PMU_DDS_INTERFACES '192.168.1': '192.168.1' is not an IPv4 address (four numbers 0..255)\n"},
    {"pmuctl --link satellite list", "pmuctl: --link 'satellite': not a link profile (one of: radio, none)\n"},
    {"PMU_LINK=Radio pmuctl list", "pmuctl: PMU_LINK 'Radio': not a link profile (one of: radio, none)\n"},
    {"PMU_LINK=radio pmuctl --link lan agent", "pmuctl: --link 'lan': not a link profile (one of: radio, none)\n"},
};

TEST(PmuctlNetworkOptions, EveryBadValueIsRefusedNamingTheOptionOrVariable) {
  for (const auto& c : kBad) {
    SCOPED_TRACE(c.command);
    const auto r = pmu::test::run_capture(pmuctl(c.command));
    EXPECT_EQ(r.status, 2);
    EXPECT_EQ(r.out, c.message);
  }
}

TEST(PmuctlNetworkOptions, AnInterfaceThisMachineLacksIsRefused) {
  // The list of this machine's interfaces follows; only the start is fixed.
  const auto r = pmu::test::run_capture(pmuctl("pmuctl --interface pmu-no-such0 list"));
  EXPECT_EQ(r.status, 2);
  EXPECT_EQ(r.out.rfind("pmuctl: --interface: interface 'pmu-no-such0': no such interface, or it has no IPv4 address "
                        "(this machine: ",
                        0),
            0u)
      << r.out;
  EXPECT_NE(r.out.find("lo 127.0.0.1"), std::string::npos) << r.out;
  const auto a = pmu::test::run_capture(pmuctl("PMU_DDS_INTERFACES=192.0.2.254 pmuctl list"));
  EXPECT_EQ(a.status, 2);
  EXPECT_EQ(a.out.rfind("pmuctl: PMU_DDS_INTERFACES: interface '192.0.2.254': no interface of this machine has this "
                        "address",
                        0),
            0u)
      << a.out;
}

TEST(PmuctlNetworkOptions, HelpNamesTheOptionsAndVariables) {
  const auto r = pmu::test::run_capture(std::string(PMUCTL_PATH) + " --help");
  EXPECT_EQ(r.status, 0);
  for (const char* s : {"--peer", "--discovery-server", "--interface", "PMU_DDS_PEERS", "PMU_DISCOVERY_SERVER",
                        "PMU_DDS_INTERFACES", "fastdds discovery -i", "--link", "PMU_LINK"})
    EXPECT_NE(r.out.find(s), std::string::npos) << s << " missing from:\n" << r.out;
}

}  // namespace
