#pragma once
// Helpers for the io tests: sample paths, temporary files, and "this throws exactly E".

#include <doctest/doctest.h>

#include <filesystem>
#include <fstream>
#include <random>
#include <string>
#include <typeinfo>

#include "sewn/io/errors.hpp"

namespace sewn::io::test {

inline std::filesystem::path data(const std::string& name) { return std::filesystem::path(SEWN_IO_TEST_DATA) / name; }

inline std::string read_text(const std::filesystem::path& p) {
  std::ifstream in(p, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

/// A fresh directory under the system temp dir, removed with the object.
class TempDir {
 public:
  explicit TempDir(const std::string& tag) {
    // random_device, not a counter: several test processes may run at once
    path_ = std::filesystem::temp_directory_path() / ("sewn_io_" + tag + "_" + std::to_string(std::random_device{}()));
    std::filesystem::remove_all(path_);
    std::filesystem::create_directories(path_);
  }
  ~TempDir() {
    std::error_code ec;
    std::filesystem::remove_all(path_, ec);
  }
  TempDir(const TempDir&) = delete;
  TempDir& operator=(const TempDir&) = delete;
  [[nodiscard]] const std::filesystem::path& path() const { return path_; }
  std::filesystem::path write(const std::string& name, const std::string& content) const {
    const auto p = path_ / name;
    std::ofstream(p, std::ios::binary) << content;
    return p;
  }

 private:
  std::filesystem::path path_;
};

/// Runs f, requires that it throws an exception of exactly type E (not merely a base or a
/// sibling), and returns its message.
template <class E, class F>
std::string message_of(F&& f) {
  try {
    f();
  } catch (const std::exception& e) {
    const std::string what = e.what();
    CHECK_MESSAGE(typeid(e) == typeid(E), "threw " << typeid(e).name() << " instead of " << typeid(E).name() << ": "
                                                   << what);
    return what;
  }
  FAIL("no exception thrown, expected " << typeid(E).name());
  return {};
}

}  // namespace sewn::io::test
