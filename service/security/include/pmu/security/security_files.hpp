#pragma once
// DDS-Security (OMG DDS-Security 1.1, Fast DDS's builtin PKI-DH, Access-Permissions and
// AES-GCM-GMAC plugins): the six files a participant needs, and their start-up check.
//
// Purpose: a program that is configured for security must refuse to start with a clear
// message when a file is missing, unreadable, of the wrong kind, expired, or does not
// belong with the others, instead of Fast DDS's generic "cannot create participant" (or,
// worse, a participant that silently never matches anything). The check runs before any
// DDS participant or CAN bus is opened.
//
// Assumptions: PEM certificates and keys (ECDSA P-256 as deploy/security/make_pki.sh makes
// them; others parse too), an unencrypted private key (Fast DDS 2.9 reads it without a
// password), governance and permissions as S/MIME signed by the Permissions CA.
//
// Security considerations: Fast DDS 2.9.1 verifies permissions against the Permissions CA
// but lets any certificate that chains to it sign them (CVE-2023-24010, fixed upstream
// later, not in Debian's 2.9.1). The check therefore refuses a Permissions CA that is the
// Identity CA or that issued the identity certificate, and it accepts governance and
// permissions only when the Permissions CA itself signed them.
//
// Error handling: nothing throws; every problem is an issue (error or warning) naming the
// file. The caller prints them and refuses to start if there is any error.
//
// Worked example (the layout make_pki.sh writes):
//   security_files_in("/etc/pmu-dds/security", "pmu-service").identity_certificate
//     == "/etc/pmu-dds/security/pmu-service/cert.pem"

#include <chrono>
#include <optional>
#include <string>
#include <vector>

namespace pmu::dds {

struct SecurityFiles {
  std::string identity_ca;           // PEM certificate of the Identity CA
  std::string identity_certificate;  // this participant's certificate, issued by identity_ca
  std::string private_key;           // its private key (PEM, unencrypted)
  std::string permissions_ca;        // PEM certificate of the Permissions CA
  std::string governance;            // governance document, S/MIME signed by permissions_ca
  std::string permissions;           // this participant's permissions, S/MIME signed by permissions_ca

  // All six empty: security off.
  bool empty() const noexcept;
};

// The layout of deploy/security/make_pki.sh: DIR/identity_ca.pem, DIR/permissions_ca.pem,
// DIR/governance.p7s, DIR/NAME/cert.pem, DIR/NAME/key.pem, DIR/NAME/permissions.p7s.
SecurityFiles security_files_in(const std::string& dir, const std::string& identity);

// The six keys in the order above, with their names (also the config file's keys).
struct SecurityFileRef {
  const char* key;
  std::string SecurityFiles::*path;
};
extern const SecurityFileRef kSecurityFileKeys[6];

struct SecurityIssue {
  enum class Level { Warning, Error };
  Level level = Level::Error;
  std::string key;      // the file's key ("identity_certificate", ...)
  std::string message;  // "PATH: what is wrong", e.g. "/x/cert.pem: expired on 2020-01-02 00:00:00 UTC"
};

struct SecurityCheckOptions {
  int warn_days = 30;         // a certificate or grant that ends within this many days: warning
  std::optional<int> domain;  // when set: governance and the grant must cover this DDS domain
  std::chrono::system_clock::time_point now = std::chrono::system_clock::now();
};

// Checks `files` as described above. Empty result: everything is in order. An empty
// `files` (security off) gives no issue.
std::vector<SecurityIssue> check_security_files(const SecurityFiles& files, const SecurityCheckOptions& options = {});

bool has_errors(const std::vector<SecurityIssue>& issues) noexcept;

// What an identity's permissions grant for one topic, read the way Fast DDS 2.9's
// Access-Permissions plugin reads them (Permissions.cpp, check_create_datawriter/reader): in
// the grant for the certificate's subject, the first allow or deny rule whose <publish>
// (<subscribe>) entries name the topic (fnmatch patterns) decides, and the partitions it
// grants are those of all these entries; an entry without <partitions> grants the default
// partition ("") alone. Fast DDS only logs why it refused an endpoint; this lets a message
// say it. nullopt when the files give no answer (unreadable, not signed by permissions_ca,
// no grant for the subject).
struct TopicGrant {
  std::string grant;                    // the grant's name attribute
  bool allowed = false;                 // an allow rule names the topic (not a deny rule, not none)
  std::vector<std::string> partitions;  // when allowed: the partition patterns granted
};
std::optional<TopicGrant> topic_grant(const SecurityFiles& files, const std::string& topic, bool publish);

// The first of an endpoint's `partitions` (none: the default partition, "") that no pattern
// of `granted` matches, compared as Fast DDS does (fnmatch, the granted entry is the
// pattern); nullopt when every one is granted.
//   partition_not_granted({"", "*"}, {"uav1"}) == ""        (the default partition)
//   partition_not_granted({"uav1"}, {"*"})     == nullopt   ("*" matches every name and "")
std::optional<std::string> partition_not_granted(const std::vector<std::string>& partitions,
                                                 const std::vector<std::string>& granted);

}  // namespace pmu::dds
