// Scratch files of the apps tests: one folder per test process, <tmp>/sewn_test_<pid>, removed
// with everything in it when the process ends normally, so that repeated runs leave nothing
// behind and processes running at once (the release and sanitizer suites, two users) never share
// a file. SEWN_KEEP_SCRATCH=1 keeps the folder, to look at a failing test's output.
#pragma once

#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>
#include <string_view>
#include <system_error>

namespace sewn::test {

namespace scratch_detail {

struct Root {
  std::filesystem::path path =
      std::filesystem::temp_directory_path() / ("sewn_test_" + std::to_string(::getpid()));
  Root() { std::filesystem::create_directories(path); }
  ~Root() {
    const char* keep = std::getenv("SEWN_KEEP_SCRATCH");
    if (keep && std::string_view(keep) == "1") return;
    std::error_code ec;  // a destructor at exit: nothing left to report to
    std::filesystem::remove_all(path, ec);
  }
  Root(const Root&) = delete;
  Root& operator=(const Root&) = delete;
};

}  // namespace scratch_detail

/// This process's scratch folder (made on first use).
inline const std::filesystem::path& scratch_root() {
  static const scratch_detail::Root root;
  return root.path;
}

/// scratch_root()/name, with its parent folders made; the path itself is left as it is.
inline std::filesystem::path scratch(std::string_view name) {
  const std::filesystem::path p = scratch_root() / name;
  std::filesystem::create_directories(p.parent_path());
  return p;
}

/// Writes `text` to scratch(name) and returns its path.
inline std::filesystem::path scratch_file(std::string_view name, std::string_view text) {
  const std::filesystem::path p = scratch(name);
  std::ofstream(p, std::ios::binary) << text;
  return p;
}

}  // namespace sewn::test
