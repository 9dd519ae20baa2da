#pragma once
// Files for tests, written once: a scratch folder that goes when the test is
// done, and a file's bytes. No optique library: unit tests link it alone.

#include <filesystem>
#include <string>

namespace optique::testing {

// A fresh, empty folder under the system's temp folder, named `prefix`-XXXXXX;
// removed with everything in it when the value goes, unless the test has
// failed by then: a failing test's outputs (logs, run reports, captures) stay,
// and where is said. Fails the test (and holds an empty path) when it cannot be
// made.
class ScratchDir {
 public:
  explicit ScratchDir(const std::string& prefix = "optique-test");
  ~ScratchDir();
  ScratchDir(const ScratchDir&) = delete;
  ScratchDir& operator=(const ScratchDir&) = delete;

  [[nodiscard]] const std::filesystem::path& path() const { return path_; }
  [[nodiscard]] std::string string() const { return path_.string(); }
  [[nodiscard]] std::string file(const std::string& name) const { return (path_ / name).string(); }

 private:
  std::filesystem::path path_;
};

// The file's bytes as they are (binary); empty when it cannot be read.
[[nodiscard]] std::string read_file(const std::filesystem::path& path);

}  // namespace optique::testing
