#pragma once
// The message-signing key file (--signing-key, `signing_key:`; interface.md 12.6) and its
// check at start, before any endpoint or DDS participant is opened, as the DDS-Security files
// are checked: a key that is missing, unreadable, readable by others or not a passphrase is
// a refusal to start with the reason, not a component that silently signs nothing.
//
// Format: the passphrase, one line of printable ASCII (a final newline is not part of it);
// the 32-byte key is SHA-256 of its bytes, as Mission Planner ("MAVLink Signing", ADD),
// MAVProxy (`signing setup PASSPHRASE`) and node-mavlink (MavLinkPacketSignature.key) derive
// theirs, so the same passphrase is the same key there. QGroundControl's releases differ in
// how they derive a key from a passphrase; a ground station that takes the key itself in hex
// gets `printf '%s' PASSPHRASE | sha256sum`.
//
// Total: every path gives the key or issues saying "PATH: what"; nothing throws. Any thread.
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "pmu/mavlink/signing.hpp"

namespace pmu::mavlink_bridge {

// A bound well above any passphrase a person types: a key file larger than this is the
// wrong file.
inline constexpr std::size_t kMaxSigningKeyFileBytes = 1024;
// Shorter passphrases are warned about: SHA-256 of a passphrase has no salt and no work
// factor, so one recorded signed frame lets a guesser test passphrases offline.
inline constexpr std::size_t kMinSigningPassphraseLength = 12;

struct SigningKeyIssue {
  bool error = true;    // false: a warning, the start goes on
  std::string message;  // "PATH: what is wrong"
};

struct SigningKeyFile {
  std::optional<pmu::mavlink::SecretKey> key;  // set when there is no error
  std::vector<SigningKeyIssue> issues;
};

// SHA-256 of the passphrase's bytes.
pmu::mavlink::SecretKey signing_key_from_passphrase(std::string_view passphrase) noexcept;

// The passphrase in a key file's text, or the reason it holds none ("is empty", "holds more
// than one line", ...), to follow "PATH: ".
struct PassphraseText {
  std::string passphrase;
  std::string error;
};
PassphraseText passphrase_in(std::string_view text);

// Reads and checks the key file at `path`: it exists, is a regular file of at most
// kMaxSigningKeyFileBytes, gives no permission to group or others, and holds a passphrase.
SigningKeyFile read_signing_key_file(const std::string& path);

}  // namespace pmu::mavlink_bridge
