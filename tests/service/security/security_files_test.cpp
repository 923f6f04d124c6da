// The start-up check of the DDS-Security files (pmu::dds::check_security_files), the
// governance document make_pki.sh writes, and pmu-service refusing bad files. No DDS
// participant is created here (this runs in the sanitizer build too).
#include <gtest/gtest.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <tinyxml2.h>
#include <unistd.h>

#include <chrono>
#include <fstream>
#include <optional>
#include <set>
#include <string>
#include <utility>
#include <vector>

#include "support/pki_fixture.hpp"
#include "pmu/security/security_files.hpp"

namespace pmu::security_test {
namespace {

using namespace std::chrono_literals;

TEST(Governance, NoUnauthenticatedParticipantsJoinControlEverythingProtected) {
  tinyxml2::XMLDocument doc;
  ASSERT_EQ(doc.LoadFile((Pki::get().dir() + "/governance.xml").c_str()), tinyxml2::XML_SUCCESS);
  const auto* rule = doc.RootElement()->FirstChildElement("domain_access_rules")->FirstChildElement("domain_rule");
  ASSERT_NE(rule, nullptr);
  auto text = [](const tinyxml2::XMLElement* e, const char* name) {
    const auto* c = e->FirstChildElement(name);
    return std::string(c && c->GetText() ? c->GetText() : "");
  };
  EXPECT_EQ(text(rule, "allow_unauthenticated_participants"), "false");
  EXPECT_EQ(text(rule, "enable_join_access_control"), "true");
  EXPECT_EQ(text(rule, "discovery_protection_kind"), "ENCRYPT");
  EXPECT_EQ(text(rule, "liveliness_protection_kind"), "ENCRYPT");
  EXPECT_EQ(text(rule, "rtps_protection_kind"), "ENCRYPT");
  std::set<std::string> seen;
  for (const auto* t = rule->FirstChildElement("topic_access_rules")->FirstChildElement("topic_rule"); t;
       t = t->NextSiblingElement("topic_rule")) {
    const std::string expr = text(t, "topic_expression");
    seen.insert(expr);
    SCOPED_TRACE(expr);
    EXPECT_EQ(text(t, "enable_read_access_control"), "true");
    EXPECT_EQ(text(t, "enable_write_access_control"), "true");
    EXPECT_EQ(text(t, "enable_discovery_protection"), "true");
    EXPECT_EQ(text(t, "data_protection_kind"), "ENCRYPT");
    if (expr == "pmu/command" || expr == "pmu/command_reply") {
      EXPECT_EQ(text(t, "metadata_protection_kind"), "ENCRYPT");
    }
  }
  EXPECT_TRUE(seen.count("pmu/command") && seen.count("pmu/command_reply") && seen.count("*"));
  // And the signed copy is what the start-up check accepts for this domain.
  dds::SecurityCheckOptions o;
  o.domain = pmu::test::exclusive_dds_domain();
  const auto issues = dds::check_security_files(Pki::get().files("pmu-service"), o);
  for (const auto& i : issues) ADD_FAILURE() << i.key << ": " << i.message;
}

// Each identity's permissions document: one grant for its certificate's subject, default
// DENY, and exactly the contract's topics to publish and to subscribe. (Fast DDS 2.9.1
// does not consult <default>, so only this test notices it turned to ALLOW.)
TEST(PermissionsDocuments, DefaultDenyAndExactlyTheContractsTopics) {
  for (const char* id : {"pmu-service", "ground-station", "mission-computer"}) {
    SCOPED_TRACE(id);
    tinyxml2::XMLDocument doc;
    ASSERT_EQ(doc.LoadFile((Pki::get().dir() + "/" + id + "/permissions.xml").c_str()), tinyxml2::XML_SUCCESS);
    const auto* perms = doc.RootElement()->FirstChildElement("permissions");
    ASSERT_NE(perms, nullptr);
    const auto* grant = perms->FirstChildElement("grant");
    ASSERT_NE(grant, nullptr);
    EXPECT_EQ(grant->NextSiblingElement("grant"), nullptr) << "one grant per identity";
    EXPECT_STREQ(grant->FirstChildElement("subject_name")->GetText(), (std::string("CN=") + id + ",O=pmu-dds").c_str());
    ASSERT_NE(grant->FirstChildElement("default"), nullptr);
    EXPECT_STREQ(grant->FirstChildElement("default")->GetText(), "DENY");
    EXPECT_EQ(grant->FirstChildElement("deny_rule"), nullptr);
    std::set<std::string> publish, subscribe;
    for (const auto* rule = grant->FirstChildElement("allow_rule"); rule; rule = rule->NextSiblingElement("allow_rule"))
      for (const auto* kind = rule->FirstChildElement(); kind; kind = kind->NextSiblingElement()) {
        const std::string k = kind->Name();
        if (k != "publish" && k != "subscribe") continue;
        for (const auto* t = kind->FirstChildElement("topics")->FirstChildElement("topic"); t;
             t = t->NextSiblingElement("topic"))
          (k == "publish" ? publish : subscribe).insert(t->GetText());
      }
    std::set<std::string> want_publish, want_subscribe;
    for (const auto& t : kContractTopics) {
      if (allowed(id, t, true)) want_publish.insert(t);
      if (allowed(id, t, false)) want_subscribe.insert(t);
    }
    EXPECT_EQ(publish, want_publish);
    EXPECT_EQ(subscribe, want_subscribe);
  }
}

// ---- the start-up check ---------------------------------------------------------------------

std::vector<dds::SecurityIssue> check(const SecurityFiles& f, int warn_days = 30) {
  dds::SecurityCheckOptions o;
  o.warn_days = warn_days;
  o.domain = pmu::test::exclusive_dds_domain();
  return dds::check_security_files(f, o);
}

std::string describe(const std::vector<dds::SecurityIssue>& issues) {
  std::string s;
  for (const auto& i : issues)
    s += std::string(i.level == dds::SecurityIssue::Level::Error ? "error " : "warning ") + i.key + ": " + i.message +
         "\n";
  return s;
}

// The one error expected, naming `key` and containing `text`.
void expect_error(const std::vector<dds::SecurityIssue>& issues, const std::string& key, const std::string& text) {
  ASSERT_TRUE(dds::has_errors(issues)) << describe(issues);
  bool found = false;
  for (const auto& i : issues)
    found = found ||
            (i.level == dds::SecurityIssue::Level::Error && i.key == key && i.message.find(text) != std::string::npos);
  EXPECT_TRUE(found) << "expected an error for " << key << " containing '" << text << "', got:\n" << describe(issues);
}

TEST(StartupCheck, TheGeneratedFilesPassForEveryIdentity) {
  for (const char* id : {"pmu-service", "ground-station", "mission-computer"}) {
    const auto issues = check(Pki::get().files(id));
    EXPECT_TRUE(issues.empty()) << id << ":\n" << describe(issues);
  }
  EXPECT_TRUE(check(SecurityFiles{}).empty()) << "no files: security off, nothing to say";
}

TEST(StartupCheck, MissingOrIncompleteFiles) {
  auto f = Pki::get().files("pmu-service");
  f.permissions = Pki::get().root() + "/nowhere/permissions.p7s";
  expect_error(check(f), "permissions", "nowhere/permissions.p7s: does not exist");
  f = Pki::get().files("pmu-service");
  f.governance = Pki::get().dir();  // a folder
  expect_error(check(f), "governance", ": cannot be read: it is a directory, not a regular file");
  // A device is never read: /dev/zero would never end (docs/safety.md H12).
  f = Pki::get().files("pmu-service");
  f.governance = "/dev/zero";
  expect_error(check(f), "governance", "/dev/zero: cannot be read: it is a character device, not a regular file");
  f = Pki::get().files("pmu-service");
  f.private_key.clear();
  expect_error(check(f), "private_key", "private_key is not set");
}

TEST(StartupCheck, UnreadableFile) {
  // A copy of the key nobody may read, in a folder anyone may enter. Root reads any file,
  // so as root the check runs in a child that has become `nobody` first.
  char dir[] = "/tmp/pmu-security-unreadable-XXXXXX";
  ASSERT_NE(::mkdtemp(dir), nullptr);
  ::chmod(dir, 0755);
  const std::string copy = std::string(dir) + "/key.pem";
  ASSERT_EQ(sh("cp " + Pki::get().files("pmu-service").private_key + " " + copy + " && chmod 000 " + copy).status, 0);
  auto f = Pki::get().files("pmu-service");
  f.private_key = copy;
  auto unreadable_reported = [&] {
    for (const auto& i : check(f))
      if (i.key == "private_key" && i.message == copy + ": cannot be read: Permission denied") return true;
    return false;
  };
  if (::geteuid() != 0) {
    EXPECT_TRUE(unreadable_reported()) << describe(check(f));
  } else {
    const pid_t child = ::fork();
    if (child == 0) {
      const bool dropped = ::setgid(65534) == 0 && ::setuid(65534) == 0;
      std::_Exit(!dropped ? 2 : unreadable_reported() ? 0 : 1);
    }
    int status = 0;
    ::waitpid(child, &status, 0);
    EXPECT_TRUE(WIFEXITED(status) && WEXITSTATUS(status) != 2) << "could not become nobody";
    EXPECT_TRUE(WIFEXITED(status) && WEXITSTATUS(status) == 0) << "no 'cannot be read' error for " << copy;
  }
  sh(std::string("rm -rf ") + dir);
}

TEST(StartupCheck, WrongKindsOfFile) {
  auto f = Pki::get().files("pmu-service");
  f.identity_certificate = f.private_key;
  expect_error(check(f), "identity_certificate", "is not a PEM certificate");
  f = Pki::get().files("pmu-service");
  f.governance = Pki::get().dir() + "/governance.xml";  // unsigned
  expect_error(check(f), "governance", "is not an S/MIME signed document");
  f = Pki::get().files("pmu-service");
  f.private_key = Pki::get().files("ground-station").private_key;
  expect_error(check(f), "private_key", "is not the key of identity_certificate");
  f = Pki::get().files("pmu-service");
  f.permissions = Pki::get().files("ground-station").permissions;
  expect_error(check(f), "permissions", "has no grant for CN=pmu-service,O=pmu-dds");
}

TEST(StartupCheck, ExpiredAndNotYetValidCertificatesAreErrorsNearExpiryIsAWarning) {
  const auto now = std::chrono::system_clock::now();
  const std::string expired = Pki::get().window("expired-2020", std::chrono::system_clock::from_time_t(1577836800),
                                                std::chrono::system_clock::from_time_t(1577923200));
  expect_error(check(dds::security_files_in(expired, "ground-station")), "identity_certificate",
               "expired on 2020-01-02 00:00:00 UTC");
  const std::string future = Pki::get().window("future", now + 24h * 2, now + 24h * 30);
  expect_error(check(dds::security_files_in(future, "ground-station")), "identity_certificate", "not valid before");
  const std::string soon = Pki::get().window("soon", now - 1h, now + 24h * 10 - 1h);
  const auto issues = check(dds::security_files_in(soon, "ground-station"), 30);
  EXPECT_FALSE(dds::has_errors(issues)) << describe(issues);
  ASSERT_EQ(issues.size(), 1u) << describe(issues);
  EXPECT_EQ(issues[0].key, "identity_certificate");
  EXPECT_NE(issues[0].message.find("(in 9 days)"), std::string::npos) << issues[0].message;
  EXPECT_TRUE(check(dds::security_files_in(soon, "ground-station"), 5).empty()) << "warn_days 5: nothing to say";
}

TEST(StartupCheck, ForeignCertificatesAndSignatures) {
  const std::string foreign = Pki::get().foreign();
  auto f = Pki::get().files("ground-station");
  f.identity_certificate = dds::security_files_in(foreign, "ground-station").identity_certificate;
  f.private_key = dds::security_files_in(foreign, "ground-station").private_key;
  expect_error(check(f), "identity_certificate", "is not issued by identity_ca");
  f = Pki::get().files("ground-station");
  f.governance = dds::security_files_in(foreign, "ground-station").governance;
  expect_error(check(f), "governance", "is not signed by permissions_ca");
}

TEST(StartupCheck, OneCaForBothRolesOrSelfSignedPermissionsAreRefused) {
  auto f = Pki::get().files("mission-computer");
  f.permissions_ca = f.identity_ca;
  expect_error(check(f), "permissions_ca", "CVE-2023-24010");
  const std::string self = Pki::get().selfsigned();
  f = Pki::get().files("mission-computer");
  f.permissions = dds::security_files_in(self, "mission-computer").permissions;
  expect_error(check(f), "permissions", "is not signed by permissions_ca");
}

TEST(StartupCheck, DomainOutsideGovernanceAndPermissions) {
  dds::SecurityCheckOptions o;
  o.domain = pmu::test::exclusive_dds_domain() + 1;
  const auto issues = dds::check_security_files(Pki::get().files("pmu-service"), o);
  expect_error(issues, "governance",
               "has no domain_rule for DDS domain " + std::to_string(pmu::test::exclusive_dds_domain() + 1));
  expect_error(issues, "permissions", "allows nothing on DDS domain");
}

// ---- vehicles: the partitions of every rule ---------------------------------------------------

// What one permissions.xml grants: its subject, the topics to publish and to subscribe, and
// the partitions of each <publish>/<subscribe> entry ({"(none)"} for an entry without
// <partitions>, which Fast DDS 2.9 reads as the default partition alone).
struct Granted {
  std::string subject;
  std::set<std::string> publish, subscribe;
  std::vector<std::set<std::string>> partitions;
};

Granted read_permissions(const std::string& path) {
  Granted g;
  tinyxml2::XMLDocument doc;
  if (doc.LoadFile(path.c_str()) != tinyxml2::XML_SUCCESS) {
    ADD_FAILURE() << path << ": not XML";
    return g;
  }
  const auto* grant = doc.RootElement()->FirstChildElement("permissions")->FirstChildElement("grant");
  g.subject = grant->FirstChildElement("subject_name")->GetText();
  for (const auto* rule = grant->FirstChildElement("allow_rule"); rule; rule = rule->NextSiblingElement("allow_rule"))
    for (const auto* entry = rule->FirstChildElement(); entry; entry = entry->NextSiblingElement()) {
      const std::string k = entry->Name();
      if (k != "publish" && k != "subscribe") continue;
      for (const auto* t = entry->FirstChildElement("topics")->FirstChildElement("topic"); t;
           t = t->NextSiblingElement("topic"))
        (k == "publish" ? g.publish : g.subscribe).insert(t->GetText());
      std::set<std::string> parts;
      const auto* ps = entry->FirstChildElement("partitions");
      if (!ps) parts.insert("(none)");
      for (const auto* p = ps ? ps->FirstChildElement("partition") : nullptr; p; p = p->NextSiblingElement("partition"))
        parts.insert(p->GetText() ? p->GetText() : "");
      g.partitions.push_back(parts);
    }
  return g;
}

// The topics of `role` in the contract (publish, subscribe).
std::pair<std::set<std::string>, std::set<std::string>> contract_topics(const std::string& role) {
  std::set<std::string> publish, subscribe;
  for (const auto& t : kContractTopics) {
    if (allowed(role, t, true)) publish.insert(t);
    if (allowed(role, t, false)) subscribe.insert(t);
  }
  return {publish, subscribe};
}

// `identity` of the PKI in `dir` has the rights of `role` (contract topics) and every entry
// grants exactly `partitions`.
void expect_grant(const std::string& dir, const std::string& identity, const std::string& role,
                  const std::set<std::string>& partitions) {
  SCOPED_TRACE(dir + " " + identity);
  const Granted g = read_permissions(dir + "/" + identity + "/permissions.xml");
  EXPECT_EQ(g.subject, "CN=" + identity + ",O=pmu-dds");
  const auto [publish, subscribe] = contract_topics(role);
  EXPECT_EQ(g.publish, publish);
  EXPECT_EQ(g.subscribe, subscribe);
  EXPECT_FALSE(g.partitions.empty());
  for (const auto& p : g.partitions) EXPECT_EQ(p, partitions);
}

// Without options every identity may use every vehicle: "*" matches every partition name and
// the default partition (Fast DDS 2.9 compares with fnmatch("*", "") == 0). A rule without
// <partitions> would allow the default partition alone, and pmuctl, which reads every
// vehicle in partitions "" and "*", could not start.
TEST(PermissionsDocuments, EveryRuleGrantsEveryVehicleByDefault) {
  for (const char* id : {"pmu-service", "ground-station", "mission-computer"})
    expect_grant(Pki::get().dir(), id, id, {"*"});
  const auto g = dds::topic_grant(Pki::get().files("ground-station"), "pmu/command_reply", false);
  ASSERT_TRUE(g.has_value());
  EXPECT_TRUE(g->allowed);
  EXPECT_EQ(g->partitions, std::vector<std::string>{"*"});
  EXPECT_EQ(dds::partition_not_granted({"", "*"}, g->partitions), std::nullopt);
  const auto mc = dds::topic_grant(Pki::get().files("mission-computer"), "pmu/command", true);
  ASSERT_TRUE(mc.has_value());
  EXPECT_FALSE(mc->allowed);
}

TEST(MakePki, VehiclesConfineTheThreeIdentities) {
  // An empty name in the list is the unnamed vehicle: an empty <partition>, the default one.
  const std::string with_unnamed = Pki::get().made("vehicles-unnamed", "--vehicles ,uav1,uav2");
  for (const char* id : {"pmu-service", "ground-station", "mission-computer"})
    expect_grant(with_unnamed, id, id, {"", "uav1", "uav2"});
  // Named vehicles only: the default partition is not granted.
  const std::string named = Pki::get().made("vehicles-named", "--vehicles uav1");
  for (const char* id : {"pmu-service", "ground-station", "mission-computer"}) expect_grant(named, id, id, {"uav1"});
  EXPECT_TRUE(check(dds::security_files_in(named, "pmu-service")).empty());
}

TEST(MakePki, GroundStationsConfinedToTheirVehicles) {
  const std::string dir =
      Pki::get().made("fleet", "--ground-station ground-uav1=uav1 --ground-station ground-b=uav2,uav3");
  expect_grant(dir, "ground-uav1", "ground-station", {"uav1"});
  expect_grant(dir, "ground-b", "ground-station", {"uav2", "uav3"});
  for (const char* id : {"pmu-service", "ground-station", "mission-computer"}) expect_grant(dir, id, id, {"*"});
  const auto f = dds::security_files_in(dir, "ground-uav1");
  EXPECT_TRUE(check(f).empty()) << describe(check(f));
  // What DdsContext's messages are made of, read from the signed document.
  const auto g = dds::topic_grant(f, "pmu/command", true);
  ASSERT_TRUE(g.has_value());
  EXPECT_EQ(g->grant, "ground-uav1");
  EXPECT_TRUE(g->allowed);
  EXPECT_EQ(g->partitions, std::vector<std::string>{"uav1"});
  const auto mc = dds::topic_grant(dds::security_files_in(dir, "mission-computer"), "pmu/command", true);
  ASSERT_TRUE(mc.has_value());
  EXPECT_FALSE(mc->allowed);
}

TEST(MakePki, RefusesBadVehicleAndIdentityNames) {
  struct Case {
    const char* args;
    const char* message;
  };
  const Case cases[] = {
      {"--vehicles 'uav*'", "--vehicles: vehicle 'uav*' contains '*'; a vehicle name is letters, digits"},
      {"--vehicles uav1,a-name-longer-than-15", "--vehicles: vehicle 'a-name-longer-than-15' is 21 characters"},
      {"--ground-station ground-uav1", "--ground-station 'ground-uav1': expected NAME=VEHICLE[,VEHICLE...]"},
      {"--ground-station 'g=uav[12]'", "--ground-station g: vehicle 'uav[12]' contains '['"},
      {"--ground-station pmu-service=uav1", "--ground-station: 'pmu-service' is taken"},
      {"--ground-station ca=uav1", "--ground-station: 'ca' is taken"},
      {"--ground-station ../x=uav1", "--ground-station: identity name '../x' must be 1..64 letters"},
      {"--ground-station g=uav1 --ground-station g=uav2", "--ground-station g given twice"},
  };
  for (const auto& c : cases) {
    SCOPED_TRACE(c.args);
    const std::string out = Pki::get().root() + "/refused";
    const auto r = sh(std::string("bash ") + PMU_SOURCE_DIR + "/deploy/security/make_pki.sh " + out + " " + c.args);
    EXPECT_EQ(r.status, 2) << r.out;
    EXPECT_NE(r.out.find(std::string("make_pki.sh: ") + c.message), std::string::npos) << r.out;
    EXPECT_NE(::access(out.c_str(), F_OK), 0) << "nothing is made on bad usage";
  }
}

// Fast DDS 2.9 (Permissions.cpp is_partition_in_criterias): every partition an endpoint asks
// for (none: the default partition "") must match one granted entry, the entry being the
// fnmatch pattern.
TEST(PartitionNotGranted, ComparesLikeFastDds) {
  struct Case {
    std::vector<std::string> asked, granted;
    std::optional<std::string> refused;
  };
  const Case cases[] = {
      {{}, {"*"}, std::nullopt},          {{"", "*"}, {"*"}, std::nullopt}, {{"uav1"}, {"*"}, std::nullopt},
      {{"uav1"}, {"uav1"}, std::nullopt}, {{}, {""}, std::nullopt},         {{}, {"uav1"}, ""},
      {{"", "*"}, {"uav1"}, ""},          {{"*"}, {"uav1"}, "*"},           {{"uav2"}, {"uav1"}, "uav2"},
      {{"uav?"}, {"uav1"}, "uav?"},       {{"uav1"}, {""}, "uav1"},         {{"uav2"}, {"uav1", "uav2"}, std::nullopt},
  };
  for (const auto& c : cases) {
    std::string asked;
    for (const auto& a : c.asked) asked += "'" + a + "' ";
    EXPECT_EQ(dds::partition_not_granted(c.asked, c.granted), c.refused) << "asked " << asked;
  }
}

// ---- the programs ---------------------------------------------------------------------------

TEST(ServiceProgram, RefusesToStartWithBadSecurityFilesAndSaysWhere) {
  const std::string service = PMU_SERVICE_PATH;
  auto f = Pki::get().files("pmu-service");
  f.permissions = Pki::get().root() + "/missing/permissions.p7s";
  std::string cfg = write_config("missing", f);
  auto r = sh(service + " --config " + cfg);
  EXPECT_EQ(r.status, 2) << r.out;
  EXPECT_NE(r.out.find(cfg + ":14: " + f.permissions + ": does not exist"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("not starting"), std::string::npos) << r.out;
  EXPECT_EQ(r.out.find("ready"), std::string::npos) << r.out;

  const std::string expired = Pki::get().window("expired-2020", std::chrono::system_clock::from_time_t(1577836800),
                                                std::chrono::system_clock::from_time_t(1577923200));
  f = dds::security_files_in(expired, "ground-station");
  cfg = write_config("expired", f);
  r = sh(service + " --config " + cfg + " --check-config");
  EXPECT_EQ(r.status, 2) << r.out;
  EXPECT_NE(r.out.find(cfg + ":10: " + f.identity_certificate + ": expired on 2020-01-02 00:00:00 UTC"),
            std::string::npos)
      << r.out;

  f = Pki::get().files("pmu-service");
  f.permissions_ca = f.identity_ca;
  cfg = write_config("one-ca", f);
  r = sh(service + " --config " + cfg + " --check-config");
  EXPECT_EQ(r.status, 2) << r.out;
  EXPECT_NE(r.out.find("CVE-2023-24010"), std::string::npos) << r.out;

  const auto now = std::chrono::system_clock::now();
  f = dds::security_files_in(Pki::get().window("soon", now - 1h, now + 24h * 10 - 1h), "ground-station");
  cfg = write_config("soon", f, "  warn_days: 30\n");
  r = sh(service + " --config " + cfg + " --check-config");
  EXPECT_EQ(r.status, 0) << r.out;
  EXPECT_NE(r.out.find("expires on"), std::string::npos) << "a warning, not an error: " << r.out;
  EXPECT_NE(r.out.find("DDS-Security files OK"), std::string::npos) << r.out;
}

// Fast DDS only logs a statistics writer the permissions refuse, and the participant refuses
// to start with one; --check-config finds it too, at the config line (make_pki.sh grants no
// identity the statistics topics).
TEST(ServiceProgram, CheckConfigRefusesStatisticsThePermissionsDoNotGrant) {
  const auto f = Pki::get().files("pmu-service");
  const std::string cfg =
      write_config("statistics", f, "dds_statistics: [_fastdds_statistics_history2history_latency]\n");
  const auto r = sh(std::string(PMU_SERVICE_PATH) + " --config " + cfg + " --check-config");
  EXPECT_EQ(r.status, 2) << r.out;
  EXPECT_NE(r.out.find(cfg + ":15: dds_statistics: this identity's permissions (" + f.permissions +
                       ") do not allow publishing _fastdds_statistics_history2history_latency in the default "
                       "partition"),
            std::string::npos)
      << r.out;
}

}  // namespace
}  // namespace pmu::security_test
