#include "signing/signing_key_file.hpp"

#include <openssl/sha.h>
#include <sys/stat.h>

#include <cerrno>
#include <cstring>

#include "pmu/files/bounded_file.hpp"

namespace pmu::mavlink_bridge {

pmu::mavlink::SecretKey signing_key_from_passphrase(std::string_view passphrase) noexcept {
  pmu::mavlink::SecretKey key{};
  static_assert(sizeof(key) == SHA256_DIGEST_LENGTH);
  SHA256(reinterpret_cast<const unsigned char*>(passphrase.data()), passphrase.size(), key.data());
  return key;
}

PassphraseText passphrase_in(std::string_view text) {
  // One final line end belongs to the file, not the passphrase (an editor adds it).
  if (text.size() >= 2 && text.substr(text.size() - 2) == "\r\n") {
    text.remove_suffix(2);
  } else if (!text.empty() && text.back() == '\n') {
    text.remove_suffix(1);
  }
  if (text.empty()) return {"", "holds no passphrase (the file is one line: the passphrase)"};
  if (text.find_first_of("\r\n") != std::string_view::npos)
    return {"", "holds more than one line: the file is one line, the passphrase"};
  for (std::size_t i = 0; i < text.size(); ++i) {
    const auto c = static_cast<unsigned char>(text[i]);
    if (c < 0x20 || c > 0x7E)
      return {"", "character " + std::to_string(i + 1) +
                      " of the passphrase is not printable ASCII (MAVProxy takes passphrases as ASCII)"};
  }
  if (text.front() == ' ' || text.back() == ' ')
    return {"", "the passphrase begins or ends with a space, which a ground station's passphrase field may not keep"};
  return {std::string(text), ""};
}

SigningKeyFile read_signing_key_file(const std::string& path) {
  SigningKeyFile out;
  auto error = [&](std::string what) { out.issues.push_back({true, path + ": " + std::move(what)}); };
  struct stat st {};
  if (::stat(path.c_str(), &st) != 0) {
    error(errno == ENOENT ? "does not exist" : std::string("cannot be read: ") + std::strerror(errno));
    return out;
  }
  // Through the one bounded reader: a device or FIFO named as the key must not stop the
  // start (docs/safety.md H12).
  const auto file = pmu::files::read_bounded_file(path, kMaxSigningKeyFileBytes);
  if (!file.ok()) {
    error("cannot be read: " + file.error);
    return out;
  }
  if ((st.st_mode & (S_IRWXG | S_IRWXO)) != 0)
    error("is accessible by group or others, and a signing key is a secret (chmod 600 it)");
  if (file.text.empty()) {
    error("is empty");
    return out;
  }
  const auto text = passphrase_in(file.text);
  if (!text.error.empty()) {
    error(text.error);
    return out;
  }
  if (text.passphrase.size() < kMinSigningPassphraseLength)
    out.issues.push_back({false, path + ": the passphrase has " + std::to_string(text.passphrase.size()) +
                                     " characters; one recorded signed frame lets a guesser test passphrases "
                                     "offline, so use " +
                                     std::to_string(kMinSigningPassphraseLength) + " or more"});
  for (const auto& i : out.issues)
    if (i.error) return out;
  out.key = signing_key_from_passphrase(text.passphrase);
  return out;
}

}  // namespace pmu::mavlink_bridge
