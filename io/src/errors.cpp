#include "sewn/io/errors.hpp"

#include <utility>

namespace sewn::io {

namespace {
std::string where(const std::string& file, std::size_t line) {
  return line > 0 ? file + ":" + std::to_string(line) : file;
}
std::string describe_found(const std::string& found) {
  return found.empty() ? "the end of the file" : "'" + found + "'";
}
}  // namespace

IoError::IoError(std::string file, std::size_t line, const std::string& reason)
    : std::runtime_error(where(file, line) + ": " + reason), file_(std::move(file)), line_(line), reason_(reason) {}

ParseError::ParseError(std::string file, std::size_t line, std::string expected, std::string found)
    : IoError(std::move(file), line, "expected " + expected + ", found " + describe_found(found)),
      expected_(std::move(expected)),
      found_(std::move(found)) {}

}  // namespace sewn::io
