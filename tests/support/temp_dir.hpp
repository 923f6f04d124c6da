#pragma once
// pmu::test_support: a folder of the test's own under /tmp, removed with everything in it when
// the TempDir goes out of scope.
//
//   pmu::test::TempDir dir("pmu-agent-test");                    // /tmp/pmu-agent-test.XXXXXX
//   const std::string file = dir.write("pmu1.yaml", "device: {serial: 1001}\n");
#include <stdlib.h>

#include <filesystem>
#include <fstream>
#include <string>
#include <system_error>

namespace pmu::test {

class TempDir {
 public:
  explicit TempDir(const std::string& prefix = "pmu-test") {
    std::string templ = "/tmp/" + prefix + ".XXXXXX";
    if (::mkdtemp(templ.data()) != nullptr) path_ = templ;
  }
  ~TempDir() {
    std::error_code ec;
    if (!path_.empty()) std::filesystem::remove_all(path_, ec);
  }
  TempDir(const TempDir&) = delete;
  TempDir& operator=(const TempDir&) = delete;

  // Empty when the folder could not be made.
  const std::string& path() const { return path_; }
  // Writes `text`, byte for byte, to NAME in the folder; returns its path.
  std::string write(const std::string& name, const std::string& text) const {
    const std::string p = path_ + "/" + name;
    std::ofstream(p, std::ios::binary) << text;
    return p;
  }

 private:
  std::string path_;
};

}  // namespace pmu::test
