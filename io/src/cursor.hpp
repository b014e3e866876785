#pragma once
// Internal: a whitespace tokenizer over a whole file in memory, with line tracking, that turns
// every malformed or missing token into a ParseError naming the file, the line and what the
// grammar expected there. Readers are written as straight-line grammar code on top of it.

#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <limits>
#include <optional>
#include <string>
#include <string_view>

#include "sewn/io/errors.hpp"

namespace sewn::io::detail {

/// Reads the whole file; FileError if it is missing, a directory, or unreadable.
std::string slurp(const std::filesystem::path& path);

/// A token shortened and made printable for an error message.
std::string printable(std::string_view token);

class Cursor {
 public:
  Cursor(std::string_view text, std::string source, char comment = '\0')
      : text_(text), source_(std::move(source)), comment_(comment) {}

  [[nodiscard]] const std::string& source() const { return source_; }
  /// Line of the last token returned (1-based).
  [[nodiscard]] std::size_t line() const { return token_line_; }
  [[nodiscard]] std::size_t remaining() const { return text_.size() - pos_; }

  /// True when only whitespace (and comments) is left.
  bool at_end();
  /// The next token without consuming it; nullopt at the end.
  std::optional<std::string_view> peek();
  /// The next token if it is on the current line (nothing is consumed).
  std::optional<std::string_view> peek_on_line();
  /// The next token; ParseError (expected `what`) at the end of the file.
  std::string_view token(std::string_view what);
  /// Consumes the next token and checks it equals `word` exactly.
  void expect(std::string_view word);
  /// Parses the next token as a signed integer; ParseError if it is not one, SemanticError if
  /// it does not fit in 64 bits.
  std::int64_t integer(std::string_view what);
  /// A non-negative integer no larger than `max`: ParseError if negative or not a number,
  /// SemanticError if larger than max.
  std::uint64_t count(std::string_view what, std::uint64_t max = std::numeric_limits<std::uint32_t>::max());
  /// Parses the next token as a real number. Non-finite values ("nan", "inf", "1e999") are
  /// returned as such: the caller decides, and names the entity in its error.
  double real(std::string_view what);
  /// The rest of the current line (without the newline), consumed.
  std::string_view rest_of_line();
  /// Moves to the start of the next line.
  void skip_line();
  /// Requires that nothing but blank space is left on the current line (for line-structured
  /// formats, so a record with extra values is reported instead of shifting every later one);
  /// `after` names the record in the error.
  void end_line(std::string_view after);
  /// The next n raw bytes (for binary sections); ParseError if fewer remain.
  std::string_view raw(std::size_t n, std::string_view what);

  [[noreturn]] void fail_expected(std::string_view what, std::string_view found) const;
  [[noreturn]] void fail_expected_here(std::string_view what);
  [[noreturn]] void fail_semantic(const std::string& reason, std::size_t line = 0) const;
  [[noreturn]] void fail_unsupported(const std::string& reason, std::size_t line = 0) const;

 private:
  void skip_space();

  std::string_view text_;
  std::string source_;
  char comment_;
  std::size_t pos_ = 0;
  std::size_t line_ = 1;
  std::size_t token_line_ = 1;
};

/// Bytes-per-record lower bounds let a reader cap a reservation by what the file can hold, so a
/// huge declared count cannot allocate more than the file's own size.
inline std::size_t reservable(std::uint64_t declared, std::size_t bytes_left, std::size_t min_bytes_per_item) {
  const std::uint64_t cap = bytes_left / (min_bytes_per_item == 0 ? 1 : min_bytes_per_item) + 1;
  return static_cast<std::size_t>(declared < cap ? declared : cap);
}

}  // namespace sewn::io::detail
