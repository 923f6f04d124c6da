// The one reader of whole files (pmu::files, docs/safety.md H12): a regular file up to its
// bound gives its text; a device, a FIFO, a directory, a missing file or a file over the bound
// gives a reason, at once, and the file is not read.
#include <gtest/gtest.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <string>
#include <vector>

#include "pmu/files/bounded_file.hpp"
#include "support/temp_dir.hpp"

namespace pmu::files::bounded_file_test {
namespace {

// A FIFO in `dir` nobody writes to: opening it for reading the usual way waits for ever.
std::string fifo_in(const pmu::test::TempDir& dir, const std::string& name) {
  const std::string p = dir.path() + "/" + name;
  return ::mkfifo(p.c_str(), 0600) == 0 ? p : std::string();
}

TEST(BoundedFile, ARegularFileUpToItsBoundIsReadWhole) {
  pmu::test::TempDir dir{"pmu-files"};
  const std::string text = "a: 1\nb: [x, y]\n";
  struct Case {
    const char* what;
    std::string content;
    std::size_t bound;
  };
  const Case cases[] = {
      {"small", text, 1024},
      {"exactly the bound", std::string(4096, 'x'), 4096},
      {"empty", "", 16},
      {"with NUL bytes", std::string("a\0b", 3), 16},
      {"larger than one read", std::string(70000, 'y'), std::size_t{1} << 20},
  };
  for (const auto& c : cases) {
    SCOPED_TRACE(c.what);
    const auto got = read_bounded_file(dir.write("f", c.content), c.bound);
    EXPECT_TRUE(got.ok()) << got.error;
    EXPECT_EQ(got.text, c.content);
    EXPECT_EQ(got.system_error, 0);
  }
}

TEST(BoundedFile, WhatIsNotARegularFileWithinItsBoundIsRefusedWithItsReason) {
  pmu::test::TempDir dir{"pmu-files"};
  const std::string fifo = fifo_in(dir, "pipe");
  ASSERT_FALSE(fifo.empty()) << "mkfifo: " << std::strerror(errno);
  struct Case {
    const char* what;
    std::string path;
    std::size_t bound;
    std::string error;
    int system_error;
  };
  const Case cases[] = {
      // /dev/zero never ends: read whole it exhausts memory.
      {"a character device", "/dev/zero", std::size_t{1} << 20, "it is a character device, not a regular file", 0},
      // A FIFO with no writer: its open would block the start for ever.
      {"a FIFO", fifo, 1024, "it is a FIFO, not a regular file", 0},
      {"a directory", dir.path(), 1024, "it is a directory, not a regular file", 0},
      {"a missing file", dir.path() + "/none", 1024, std::strerror(ENOENT), ENOENT},
      {"one byte over the bound", dir.write("big", std::string(1025, 'x')), 1024,
       "it is 1025 bytes, larger than the 1 KiB bound", 0},
      {"far over the bound", dir.write("huge", std::string(3u << 20, 'x')), std::size_t{1} << 20,
       "it is 3 MiB, larger than the 1 MiB bound", 0},
  };
  for (const auto& c : cases) {
    SCOPED_TRACE(c.what);
    const auto got = read_bounded_file(c.path, c.bound);
    EXPECT_FALSE(got.ok());
    EXPECT_EQ(got.error, c.error);
    EXPECT_EQ(got.system_error, c.system_error);
    EXPECT_TRUE(got.text.empty());
  }
}

TEST(BoundedFile, AFileThatCannotBeOpenedSaysWhy) {
  if (::geteuid() == 0) GTEST_SKIP() << "root opens a file of mode 000: no EACCES to see";
  pmu::test::TempDir dir{"pmu-files"};
  const std::string file = dir.write("locked", "x");
  ASSERT_EQ(::chmod(file.c_str(), 0), 0);
  const auto got = read_bounded_file(file, 1024);
  EXPECT_EQ(got.error, std::strerror(EACCES));
  EXPECT_EQ(got.system_error, EACCES);
}

TEST(BoundedFile, ABoundIsSaidInItsLargestWholeUnit) {
  const std::pair<std::size_t, const char*> cases[] = {{1, "1 byte"},        {100, "100 bytes"}, {1024, "1 KiB"},
                                                       {1536, "1536 bytes"}, {65536, "64 KiB"},  {1u << 20, "1 MiB"}};
  for (const auto& [bytes, text] : cases) EXPECT_EQ(size_text(bytes), text) << bytes;
}

}  // namespace
}  // namespace pmu::files::bounded_file_test
