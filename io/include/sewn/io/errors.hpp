#pragma once
// Exceptions thrown by the mesh readers and writers. Each message is complete on its own:
// "<file>:<line>: <reason>", so a tool can print what() and exit.
//
//   IoError                 base of everything a file can cause (catch this in the tool)
//   ├─ FileError            the file cannot be opened, read or written
//   ├─ ParseError           the bytes break the format's grammar (bad token, truncation, a
//   │                       missing section, a negative count); carries what was expected
//   ├─ SemanticError        grammatical, but the content is inconsistent (an index out of
//   │                       range, an unknown element type, a count that disagrees with the
//   │                       data, a non-finite coordinate, a duplicate node tag)
//   └─ UnsupportedError     a valid file using something Sewn does not read (a format
//                           version, binary MSH, higher-order elements, ...)

#include <cstddef>
#include <stdexcept>
#include <string>

namespace sewn::io {

class IoError : public std::runtime_error {
 public:
  /// `line` is 1-based; 0 when the problem has no line (a whole-file or binary-data problem).
  IoError(std::string file, std::size_t line, const std::string& reason);
  [[nodiscard]] const std::string& file() const noexcept { return file_; }
  [[nodiscard]] std::size_t line() const noexcept { return line_; }
  /// The reason alone, without the "file:line: " prefix.
  [[nodiscard]] const std::string& reason() const noexcept { return reason_; }

 private:
  std::string file_;
  std::size_t line_;
  std::string reason_;
};

class FileError : public IoError {
 public:
  using IoError::IoError;
};

class ParseError : public IoError {
 public:
  /// `expected` says what the grammar wanted there, `found` what was there ("" at end of file).
  ParseError(std::string file, std::size_t line, std::string expected, std::string found);
  [[nodiscard]] const std::string& expected() const noexcept { return expected_; }
  [[nodiscard]] const std::string& found() const noexcept { return found_; }

 private:
  std::string expected_;
  std::string found_;
};

class SemanticError : public IoError {
 public:
  using IoError::IoError;
};

class UnsupportedError : public IoError {
 public:
  using IoError::IoError;
};

}  // namespace sewn::io
