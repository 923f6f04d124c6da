// The signing key file (interface.md 12.6): a passphrase on one line, SHA-256 of it the key,
// checked at start with one error each saying what and where.

#include "signing/signing_key_file.hpp"

#include <gtest/gtest.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cstdlib>
#include <fstream>
#include <string>

namespace pmu::mavlink_bridge {
// A named namespace: the unity builds put this file beside others of the target.
namespace signing_key_file_test {

// A folder of its own for each test's files, removed at the end.
class KeyFolder {
 public:
  KeyFolder() {
    char pattern[] = "/tmp/pmu-signing-key-XXXXXX";
    const char* made = ::mkdtemp(pattern);
    EXPECT_NE(made, nullptr);
    dir_ = made != nullptr ? made : "/tmp";
  }
  ~KeyFolder() { std::system(("rm -rf '" + dir_ + "'").c_str()); }
  KeyFolder(const KeyFolder&) = delete;
  KeyFolder& operator=(const KeyFolder&) = delete;

  std::string write(const std::string& name, const std::string& text, mode_t mode = 0600) const {
    const std::string path = dir_ + "/" + name;
    std::ofstream(path, std::ios::binary) << text;
    ::chmod(path.c_str(), mode);
    return path;
  }
  std::string path(const std::string& name) const { return dir_ + "/" + name; }

 private:
  std::string dir_;
};

std::string hex(const pmu::mavlink::SecretKey& key) {
  static const char* digits = "0123456789abcdef";
  std::string out;
  for (const auto b : key) {
    out += digits[b >> 4];
    out += digits[b & 0xF];
  }
  return out;
}

TEST(SigningKeyFile, TheKeyIsSha256OfThePassphrase) {
  // FIPS 180-2's example: SHA-256("abc"); what `printf '%s' abc | sha256sum` prints.
  EXPECT_EQ(hex(signing_key_from_passphrase("abc")),
            "ba7816bf8f01cfea414140de5dae2223b00361a396177a9cb410ff61f20015ad");
}

TEST(SigningKeyFile, OneLineAFinalLineEndNotPartOfIt) {
  KeyFolder dir;
  const auto expected = signing_key_from_passphrase("correct horse battery staple");
  for (const char* text :
       {"correct horse battery staple", "correct horse battery staple\n", "correct horse battery staple\r\n"}) {
    const auto file = read_signing_key_file(dir.write("k", text));
    ASSERT_TRUE(file.key) << text;
    EXPECT_EQ(*file.key, expected) << text;
    EXPECT_TRUE(file.issues.empty()) << file.issues.front().message;
  }
}

TEST(SigningKeyFile, EachProblemOneErrorNamingTheFile) {
  KeyFolder dir;
  ::mkdir(dir.path("a-folder").c_str(), 0700);
  ::mkfifo(dir.path("a-fifo").c_str(), 0600);
  const struct {
    std::string path;
    const char* expected;
  } cases[] = {
      {dir.path("missing"), ": does not exist"},
      {dir.path("a-folder"), ": cannot be read: "},
      {dir.path("a-fifo"), ": cannot be read: "},
      {dir.write("readable", "correct horse battery staple\n", 0644),
       ": is accessible by group or others, and a signing key is a secret (chmod 600 it)"},
      {dir.write("group", "correct horse battery staple\n", 0640), ": is accessible by group or others"},
      {dir.write("empty", ""), ": is empty"},
      {dir.write("blank", "\n"), ": holds no passphrase"},
      {dir.write("two-lines", "correct horse\nbattery staple\n"), ": holds more than one line"},
      {dir.write("large", std::string(kMaxSigningKeyFileBytes + 1, 'x')), ": cannot be read: "},
      {dir.write("tab", "correct horse\tbattery staple"), ": character 14 of the passphrase is not printable ASCII"},
      {dir.write("utf8", "correct horse b\xc3\xa4ttery"), ": character 16 of the passphrase is not printable ASCII"},
      {dir.write("space", " correct horse battery staple"), ": the passphrase begins or ends with a space"},
  };
  for (const auto& c : cases) {
    const auto file = read_signing_key_file(c.path);
    EXPECT_FALSE(file.key) << c.path;
    ASSERT_EQ(file.issues.size(), 1U) << c.path;
    EXPECT_TRUE(file.issues[0].error) << c.path;
    EXPECT_EQ(file.issues[0].message.rfind(c.path + c.expected, 0), 0U) << file.issues[0].message;
  }
}

TEST(SigningKeyFile, TheBoundIsSaid) {
  KeyFolder dir;
  const auto file = read_signing_key_file(dir.write("large", std::string(kMaxSigningKeyFileBytes + 1, 'x')));
  ASSERT_EQ(file.issues.size(), 1U);
  EXPECT_NE(file.issues[0].message.find("1 KiB"), std::string::npos) << file.issues[0].message;
}

TEST(SigningKeyFile, AShortPassphraseIsAWarning) {
  KeyFolder dir;
  const auto file = read_signing_key_file(dir.write("short", "abc\n"));
  ASSERT_TRUE(file.key) << "a warning does not stop the start";
  EXPECT_EQ(*file.key, signing_key_from_passphrase("abc"));
  ASSERT_EQ(file.issues.size(), 1U);
  EXPECT_FALSE(file.issues[0].error);
  EXPECT_NE(file.issues[0].message.find("has 3 characters"), std::string::npos) << file.issues[0].message;
}

}  // namespace signing_key_file_test
}  // namespace pmu::mavlink_bridge
