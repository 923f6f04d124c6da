#include "pmu/security/security_files.hpp"

#include <openssl/bio.h>
#include <openssl/buffer.h>
#include <openssl/err.h>
#include <openssl/evp.h>
#include <openssl/pem.h>
#include <openssl/pkcs7.h>
#include <openssl/x509.h>
#include <openssl/x509_vfy.h>
#include <openssl/x509v3.h>
#include <fnmatch.h>
#include <sys/stat.h>
#include <tinyxml2.h>

#include "pmu/files/bounded_file.hpp"

#include <algorithm>
#include <cerrno>
#include <cstring>
#include <ctime>
#include <fstream>
#include <memory>
#include <utility>

namespace pmu::dds {

const SecurityFileRef kSecurityFileKeys[6] = {
    {"identity_ca", &SecurityFiles::identity_ca}, {"identity_certificate", &SecurityFiles::identity_certificate},
    {"private_key", &SecurityFiles::private_key}, {"permissions_ca", &SecurityFiles::permissions_ca},
    {"governance", &SecurityFiles::governance},   {"permissions", &SecurityFiles::permissions},
};

bool SecurityFiles::empty() const noexcept {
  return std::all_of(std::begin(kSecurityFileKeys), std::end(kSecurityFileKeys),
                     [this](const SecurityFileRef& r) { return (this->*r.path).empty(); });
}

SecurityFiles security_files_in(const std::string& dir, const std::string& identity) {
  std::string d = dir;
  while (d.size() > 1 && d.back() == '/') d.pop_back();
  SecurityFiles f;
  f.identity_ca = d + "/identity_ca.pem";
  f.identity_certificate = d + "/" + identity + "/cert.pem";
  f.private_key = d + "/" + identity + "/key.pem";
  f.permissions_ca = d + "/permissions_ca.pem";
  f.governance = d + "/governance.p7s";
  f.permissions = d + "/" + identity + "/permissions.p7s";
  return f;
}

bool has_errors(const std::vector<SecurityIssue>& issues) noexcept {
  return std::any_of(issues.begin(), issues.end(),
                     [](const SecurityIssue& i) { return i.level == SecurityIssue::Level::Error; });
}

namespace {

// A certificate, key, governance or permissions file is a few KiB; permissions for a large
// fleet stay far below this.
constexpr std::size_t kMaxSecurityFileBytes = std::size_t{1} << 20;

template <class T, void (*Free)(T*)>
struct Deleter {
  void operator()(T* p) const noexcept { Free(p); }
};
using Bio = std::unique_ptr<BIO, Deleter<BIO, BIO_free_all>>;
using Cert = std::unique_ptr<X509, Deleter<X509, X509_free>>;
using Key = std::unique_ptr<EVP_PKEY, Deleter<EVP_PKEY, EVP_PKEY_free>>;
using Store = std::unique_ptr<X509_STORE, Deleter<X509_STORE, X509_STORE_free>>;
using StoreCtx = std::unique_ptr<X509_STORE_CTX, Deleter<X509_STORE_CTX, X509_STORE_CTX_free>>;
using Pkcs7 = std::unique_ptr<PKCS7, Deleter<PKCS7, PKCS7_free>>;
using Asn1Time = std::unique_ptr<ASN1_TIME, Deleter<ASN1_TIME, ASN1_STRING_free>>;

struct CertStack {
  STACK_OF(X509) * s = sk_X509_new_null();
  ~CertStack() { sk_X509_free(s); }  // the certificates belong to their own owners
  CertStack() = default;
  CertStack(const CertStack&) = delete;
  CertStack& operator=(const CertStack&) = delete;
};

// The last OpenSSL error as text (and the queue cleared), for messages.
std::string openssl_error() {
  const unsigned long e = ERR_get_error();
  ERR_clear_error();
  if (e == 0) return "no detail";
  char buf[256];
  ERR_error_string_n(e, buf, sizeof buf);
  return buf;
}

// No passphrase prompt on the terminal: an encrypted key simply fails to load.
int no_password(char*, int, int, void*) { return -1; }

std::string format_tm(const std::tm& tm) {
  char buf[40];
  std::strftime(buf, sizeof buf, "%Y-%m-%d %H:%M:%S UTC", &tm);
  return buf;
}

std::string format_time(const ASN1_TIME* t) {
  std::tm tm{};
  if (!ASN1_TIME_to_tm(t, &tm)) return "an unreadable date";
  return format_tm(tm);
}

std::string format_time(std::time_t t) {
  std::tm tm{};
  gmtime_r(&t, &tm);
  return format_tm(tm);
}

class Checker {
 public:
  Checker(const SecurityFiles& files, const SecurityCheckOptions& o)
      : files_(files), o_(o), now_(std::chrono::system_clock::to_time_t(o.now)) {}

  std::vector<SecurityIssue> run() {
    if (files_.empty()) return {};
    bool complete = true;
    for (const auto& r : kSecurityFileKeys) {
      if ((files_.*r.path).empty()) {
        error(r.key, std::string(r.key) +
                         " is not set (security needs all six files: identity_ca, "
                         "identity_certificate, private_key, permissions_ca, governance, permissions)");
        complete = false;
      }
    }
    if (!complete) return std::move(issues_);
    bool readable = true;
    for (const auto& r : kSecurityFileKeys) readable = check_readable(r.key, files_.*r.path) && readable;
    if (!readable) return std::move(issues_);

    Cert identity_ca = load_cert("identity_ca", files_.identity_ca);
    Cert identity = load_cert("identity_certificate", files_.identity_certificate);
    Key key = load_key("private_key", files_.private_key);
    Cert permissions_ca = load_cert("permissions_ca", files_.permissions_ca);
    if (identity_ca) check_validity("identity_ca", files_.identity_ca, identity_ca.get());
    if (identity) check_validity("identity_certificate", files_.identity_certificate, identity.get());
    if (permissions_ca) check_validity("permissions_ca", files_.permissions_ca, permissions_ca.get());
    if (identity_ca && identity) check_issued_by(identity.get(), identity_ca.get());
    if (identity && key && X509_check_private_key(identity.get(), key.get()) != 1) {
      ERR_clear_error();
      error("private_key",
            files_.private_key + ": is not the key of identity_certificate " + files_.identity_certificate);
    }
    if (identity_ca && permissions_ca) check_separate_cas(identity_ca.get(), identity.get(), permissions_ca.get());
    if (permissions_ca) {
      const std::string governance = verified_content("governance", files_.governance, permissions_ca.get());
      if (!governance.empty()) check_governance(governance);
      const std::string permissions = verified_content("permissions", files_.permissions, permissions_ca.get());
      if (!permissions.empty() && identity) check_permissions(permissions, identity.get());
    }
    return std::move(issues_);
  }

  // topic_grant() of security_files.hpp. The issues found on the way are not reported: this
  // only explains a refusal after the start-up check passed.
  std::optional<TopicGrant> topic_grant(const std::string& topic, bool publish) {
    if (files_.empty()) return std::nullopt;
    Cert identity = load_cert("identity_certificate", files_.identity_certificate);
    Cert permissions_ca = load_cert("permissions_ca", files_.permissions_ca);
    if (!identity || !permissions_ca) return std::nullopt;
    const std::string xml = verified_content("permissions", files_.permissions, permissions_ca.get());
    tinyxml2::XMLDocument doc;
    if (xml.empty() || doc.Parse(xml.data(), xml.size()) != tinyxml2::XML_SUCCESS) return std::nullopt;
    const auto* perms = doc.RootElement() ? doc.RootElement()->FirstChildElement("permissions") : nullptr;
    const auto wanted = dn_parts(subject_of(identity.get()));
    for (auto* g = perms ? perms->FirstChildElement("grant") : nullptr; g; g = g->NextSiblingElement("grant")) {
      if (dn_parts(text_of(g->FirstChildElement("subject_name"))) != wanted) continue;
      TopicGrant result;
      result.grant = g->Attribute("name") ? g->Attribute("name") : "";
      const char* kind = publish ? "publish" : "subscribe";
      for (auto* rule = g->FirstChildElement(); rule; rule = rule->NextSiblingElement()) {
        const bool allow = std::strcmp(rule->Name(), "allow_rule") == 0;
        if (!allow && std::strcmp(rule->Name(), "deny_rule") != 0) continue;
        bool names_topic = false;
        std::vector<std::string> partitions;
        for (auto* c = rule->FirstChildElement(kind); c; c = c->NextSiblingElement(kind)) {
          const auto* topics = c->FirstChildElement("topics");
          for (auto* t = topics ? topics->FirstChildElement("topic") : nullptr; t; t = t->NextSiblingElement("topic"))
            names_topic = names_topic || (t->GetText() && ::fnmatch(t->GetText(), topic.c_str(), FNM_NOESCAPE) == 0);
          const auto* parts = c->FirstChildElement("partitions");
          if (!parts) partitions.emplace_back();  // Fast DDS: no <partitions>, the default partition
          for (auto* p = parts ? parts->FirstChildElement("partition") : nullptr; p;
               p = p->NextSiblingElement("partition"))
            partitions.emplace_back(p->GetText() ? p->GetText() : "");
        }
        if (!names_topic) continue;
        result.allowed = allow;
        if (allow) result.partitions = std::move(partitions);
        return result;
      }
      return result;  // no rule names the topic: not allowed
    }
    return std::nullopt;
  }

 private:
  void error(const std::string& key, std::string message) {
    issues_.push_back({SecurityIssue::Level::Error, key, std::move(message)});
  }
  void warning(const std::string& key, std::string message) {
    issues_.push_back({SecurityIssue::Level::Warning, key, std::move(message)});
  }

  bool check_readable(const char* key, const std::string& path) {
    // Through the one bounded reader: a device or FIFO named as a security file must not
    // stop the start (docs/safety.md H12).
    const auto file = files::read_bounded_file(path, kMaxSecurityFileBytes);
    if (!file.ok()) {
      error(key, path + ": " + (file.system_error == ENOENT ? "does not exist" : "cannot be read: " + file.error));
      return false;
    }
    if (file.text.empty()) {
      error(key, path + ": is empty");
      return false;
    }
    struct stat st {};
    if (std::string(key) == "private_key" && ::stat(path.c_str(), &st) == 0 && (st.st_mode & (S_IRWXG | S_IRWXO)) != 0)
      warning(key, path + ": is accessible by group or others (chmod 600 it)");
    return true;
  }

  // The file's text in a memory BIO, read by the bounded reader; null when it cannot be read.
  static Bio open(const std::string& path) {
    auto file = files::read_bounded_file(path, kMaxSecurityFileBytes);
    if (!file.ok()) return Bio(nullptr);
    // BIO_new_mem_buf keeps a pointer only: the BIO gets its own copy.
    Bio bio(BIO_new(BIO_s_mem()));
    if (bio && BIO_write(bio.get(), file.text.data(), static_cast<int>(file.text.size())) !=
                   static_cast<int>(file.text.size()))
      bio.reset();
    // Its end is the end of the file, as a file BIO's: S/MIME's reader stops at it, not retries.
    if (bio) BIO_set_mem_eof_return(bio.get(), 0);
    return bio;
  }

  Cert load_cert(const char* key, const std::string& path) {
    Bio in = open(path);
    Cert c(in ? PEM_read_bio_X509(in.get(), nullptr, no_password, nullptr) : nullptr);
    if (!c) error(key, path + ": is not a PEM certificate (" + openssl_error() + ")");
    return c;
  }

  Key load_key(const char* key, const std::string& path) {
    Bio in = open(path);
    Key k(in ? PEM_read_bio_PrivateKey(in.get(), nullptr, no_password, nullptr) : nullptr);
    if (!k)
      error(key, path + ": is not an unencrypted PEM private key (" + openssl_error() +
                     "); Fast DDS reads the key without a password");
    return k;
  }

  void check_validity(const char* key, const std::string& path, X509* cert) {
    std::time_t now = now_;
    const ASN1_TIME* not_before = X509_get0_notBefore(cert);
    const ASN1_TIME* not_after = X509_get0_notAfter(cert);
    if (X509_cmp_time(not_before, &now) > 0) {
      error(key, path + ": not valid before " + format_time(not_before));
      return;
    }
    if (X509_cmp_time(not_after, &now) < 0) {
      error(key, path + ": expired on " + format_time(not_after));
      return;
    }
    Asn1Time from(ASN1_TIME_set(nullptr, now));
    int days = 0, seconds = 0;
    if (from && ASN1_TIME_diff(&days, &seconds, from.get(), not_after) && days < o_.warn_days)
      warning(key, path + ": expires on " + format_time(not_after) + " (in " + std::to_string(days) + " days)");
  }

  // The identity certificate must chain to the Identity CA (validity is checked apart, so
  // an expired certificate gets one message, not two).
  void check_issued_by(X509* identity, X509* ca) {
    Store store(X509_STORE_new());
    StoreCtx ctx(X509_STORE_CTX_new());
    if (!store || !ctx || X509_STORE_add_cert(store.get(), ca) != 1 ||
        X509_STORE_CTX_init(ctx.get(), store.get(), identity, nullptr) != 1) {
      error("identity_certificate", files_.identity_certificate + ": cannot be verified (" + openssl_error() + ")");
      return;
    }
    X509_STORE_CTX_set_flags(ctx.get(), X509_V_FLAG_NO_CHECK_TIME);
    if (X509_verify_cert(ctx.get()) != 1) {
      const int e = X509_STORE_CTX_get_error(ctx.get());
      ERR_clear_error();
      error("identity_certificate", files_.identity_certificate + ": is not issued by identity_ca " +
                                        files_.identity_ca + " (" + X509_verify_cert_error_string(e) + ")");
    }
  }

  // CVE-2023-24010: with one CA for both roles, Fast DDS 2.9.1 accepts permissions any
  // participant signed with its own identity.
  void check_separate_cas(X509* identity_ca, X509* identity, X509* permissions_ca) {
    const std::string why =
        ": Fast DDS 2.9.1 then lets any participant sign its own permissions (CVE-2023-24010); use a separate "
        "Permissions CA that signs nothing but governance and permissions (deploy/security/make_pki.sh makes one)";
    if (X509_cmp(identity_ca, permissions_ca) == 0 ||
        EVP_PKEY_eq(X509_get0_pubkey(identity_ca), X509_get0_pubkey(permissions_ca)) == 1) {
      error("permissions_ca", files_.permissions_ca + ": is the Identity CA (" + files_.identity_ca + ")" + why);
      return;
    }
    if (identity && X509_check_issued(permissions_ca, identity) == X509_V_OK &&
        X509_verify(identity, X509_get0_pubkey(permissions_ca)) == 1) {
      error("permissions_ca",
            files_.permissions_ca + ": also issued identity_certificate " + files_.identity_certificate + why);
    }
    ERR_clear_error();
  }

  // The signed content of an S/MIME file, if the Permissions CA itself signed it.
  std::string verified_content(const char* key, const std::string& path, X509* permissions_ca) {
    Bio in = open(path);
    BIO* detached = nullptr;
    Pkcs7 p7(in ? SMIME_read_PKCS7(in.get(), &detached) : nullptr);
    Bio content(detached);
    if (!p7) {
      error(key, path + ": is not an S/MIME signed document (" + openssl_error() + ")");
      return {};
    }
    Store store(X509_STORE_new());
    CertStack signers;
    Bio out(BIO_new(BIO_s_mem()));
    if (!store || !signers.s || !out || X509_STORE_add_cert(store.get(), permissions_ca) != 1 ||
        sk_X509_push(signers.s, permissions_ca) <= 0) {
      error(key, path + ": cannot be verified (" + openssl_error() + ")");
      return {};
    }
    X509_STORE_set_flags(store.get(), X509_V_FLAG_NO_CHECK_TIME);
    // PKCS7_NOINTERN: the signer must be the Permissions CA itself, not any certificate the
    // document carries that happens to chain to it.
    if (PKCS7_verify(p7.get(), signers.s, store.get(), content.get(), out.get(), PKCS7_TEXT | PKCS7_NOINTERN) != 1) {
      error(key, path + ": is not signed by permissions_ca " + files_.permissions_ca + " (" + openssl_error() + ")");
      return {};
    }
    BUF_MEM* mem = nullptr;
    BIO_get_mem_ptr(out.get(), &mem);
    if (!mem || mem->length == 0) {
      error(key, path + ": the signed document is empty");
      return {};
    }
    return std::string(mem->data, mem->length);
  }

  static std::string text_of(const tinyxml2::XMLElement* e) {
    const char* t = e ? e->GetText() : nullptr;
    std::string s = t ? t : "";
    const auto b = s.find_first_not_of(" \t\r\n");
    const auto f = s.find_last_not_of(" \t\r\n");
    return b == std::string::npos ? std::string() : s.substr(b, f - b + 1);
  }

  // <domains><id>N</id><id_range><min>A</min><max>B</max></id_range></domains>
  static bool covers(const tinyxml2::XMLElement* domains, int domain) {
    if (!domains) return false;
    for (auto* e = domains->FirstChildElement(); e; e = e->NextSiblingElement()) {
      if (std::strcmp(e->Name(), "id") == 0 && text_of(e) == std::to_string(domain)) return true;
      if (std::strcmp(e->Name(), "id_range") == 0) {
        const std::string lo = text_of(e->FirstChildElement("min")), hi = text_of(e->FirstChildElement("max"));
        try {
          if ((lo.empty() || std::stoi(lo) <= domain) && (hi.empty() || domain <= std::stoi(hi))) return true;
        } catch (const std::exception&) {
        }
      }
    }
    return false;
  }

  void check_governance(const std::string& xml) {
    tinyxml2::XMLDocument doc;
    if (doc.Parse(xml.data(), xml.size()) != tinyxml2::XML_SUCCESS) {
      error("governance", files_.governance + ": the signed document is not XML (" + doc.ErrorStr() + ")");
      return;
    }
    const auto* rules = doc.RootElement() ? doc.RootElement()->FirstChildElement("domain_access_rules") : nullptr;
    if (!rules) {
      error("governance", files_.governance + ": has no <domain_access_rules>");
      return;
    }
    if (!o_.domain) return;
    for (auto* r = rules->FirstChildElement("domain_rule"); r; r = r->NextSiblingElement("domain_rule"))
      if (covers(r->FirstChildElement("domains"), *o_.domain)) return;
    error("governance", files_.governance + ": has no domain_rule for DDS domain " + std::to_string(*o_.domain));
  }

  // "CN=a, O=b" -> {(CN,a), (O,b)}, sorted, for an order-independent comparison.
  static std::vector<std::pair<std::string, std::string>> dn_parts(const std::string& dn) {
    std::vector<std::pair<std::string, std::string>> parts;
    std::size_t pos = 0;
    while (pos <= dn.size()) {
      std::size_t end = pos;
      while (end < dn.size() && dn[end] != ',') end += dn[end] == '\\' ? 2u : 1u;
      const std::string item = dn.substr(pos, std::min(end, dn.size()) - pos);
      const auto eq = item.find('=');
      auto trim = [](std::string s) {
        const auto b = s.find_first_not_of(' ');
        const auto f = s.find_last_not_of(' ');
        return b == std::string::npos ? std::string() : s.substr(b, f - b + 1);
      };
      if (eq != std::string::npos) parts.emplace_back(trim(item.substr(0, eq)), trim(item.substr(eq + 1)));
      pos = end + 1;
    }
    std::sort(parts.begin(), parts.end());
    return parts;
  }

  static std::string subject_of(X509* cert) {
    std::string dn;
    const X509_NAME* name = X509_get_subject_name(cert);
    for (int i = X509_NAME_entry_count(name) - 1; i >= 0; --i) {  // RFC 2253 order: last RDN first
      const X509_NAME_ENTRY* e = X509_NAME_get_entry(name, i);
      const int nid = OBJ_obj2nid(X509_NAME_ENTRY_get_object(e));
      const ASN1_STRING* v = X509_NAME_ENTRY_get_data(e);
      unsigned char* utf8 = nullptr;
      const int n = ASN1_STRING_to_UTF8(&utf8, v);
      if (n < 0) continue;
      if (!dn.empty()) dn += ",";
      dn += std::string(nid == NID_undef ? "?" : OBJ_nid2sn(nid)) + "=" +
            std::string(reinterpret_cast<const char*>(utf8), static_cast<std::size_t>(n));
      OPENSSL_free(utf8);
    }
    return dn;
  }

  static std::optional<std::time_t> parse_xml_time(const std::string& s) {
    std::tm tm{};
    const char* end = strptime(s.c_str(), "%Y-%m-%dT%H:%M:%S", &tm);
    if (!end) return std::nullopt;
    return timegm(&tm);
  }

  void check_permissions(const std::string& xml, X509* identity) {
    tinyxml2::XMLDocument doc;
    if (doc.Parse(xml.data(), xml.size()) != tinyxml2::XML_SUCCESS) {
      error("permissions", files_.permissions + ": the signed document is not XML (" + doc.ErrorStr() + ")");
      return;
    }
    const auto* perms = doc.RootElement() ? doc.RootElement()->FirstChildElement("permissions") : nullptr;
    if (!perms) {
      error("permissions", files_.permissions + ": has no <permissions>");
      return;
    }
    const std::string subject = subject_of(identity);
    const auto wanted = dn_parts(subject);
    for (auto* g = perms->FirstChildElement("grant"); g; g = g->NextSiblingElement("grant")) {
      if (dn_parts(text_of(g->FirstChildElement("subject_name"))) != wanted) continue;
      const char* name = g->Attribute("name");
      const std::string grant = std::string("grant '") + (name ? name : "") + "'";
      const auto* validity = g->FirstChildElement("validity");
      const auto from = parse_xml_time(text_of(validity ? validity->FirstChildElement("not_before") : nullptr));
      const auto until = parse_xml_time(text_of(validity ? validity->FirstChildElement("not_after") : nullptr));
      if (!from || !until) {
        error("permissions", files_.permissions + ": " + grant + " has no readable validity (not_before/not_after)");
      } else if (now_ < *from) {
        error("permissions", files_.permissions + ": " + grant + " not valid before " + format_time(*from));
      } else if (now_ > *until) {
        error("permissions", files_.permissions + ": " + grant + " expired on " + format_time(*until));
      } else if (*until - now_ < static_cast<std::time_t>(o_.warn_days) * 86400) {
        warning("permissions", files_.permissions + ": " + grant + " expires on " + format_time(*until) + " (in " +
                                   std::to_string((*until - now_) / 86400) + " days)");
      }
      if (o_.domain) {
        bool allowed = false;
        for (auto* r = g->FirstChildElement("allow_rule"); r && !allowed; r = r->NextSiblingElement("allow_rule"))
          allowed = covers(r->FirstChildElement("domains"), *o_.domain);
        if (!allowed)
          error("permissions",
                files_.permissions + ": " + grant + " allows nothing on DDS domain " + std::to_string(*o_.domain));
      }
      return;
    }
    error("permissions", files_.permissions + ": has no grant for " + subject +
                             " (the subject of identity_certificate " + files_.identity_certificate + ")");
  }

  const SecurityFiles& files_;
  const SecurityCheckOptions& o_;
  std::time_t now_;
  std::vector<SecurityIssue> issues_;
};

}  // namespace

std::vector<SecurityIssue> check_security_files(const SecurityFiles& files, const SecurityCheckOptions& options) {
  return Checker(files, options).run();
}

std::optional<TopicGrant> topic_grant(const SecurityFiles& files, const std::string& topic, bool publish) {
  const SecurityCheckOptions options;
  return Checker(files, options).topic_grant(topic, publish);
}

std::optional<std::string> partition_not_granted(const std::vector<std::string>& partitions,
                                                 const std::vector<std::string>& granted) {
  const std::vector<std::string> asked = partitions.empty() ? std::vector<std::string>{""} : partitions;
  for (const auto& p : asked) {
    const bool ok = std::any_of(granted.begin(), granted.end(), [&](const std::string& pattern) {
      return ::fnmatch(pattern.c_str(), p.c_str(), FNM_NOESCAPE) == 0;
    });
    if (!ok) return p;
  }
  return std::nullopt;
}

}  // namespace pmu::dds
