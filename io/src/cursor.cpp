#include "cursor.hpp"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstdlib>
#include <fstream>
#include <system_error>

namespace sewn::io::detail {

std::string slurp(const std::filesystem::path& path) {
  const std::string name = path.string();
  std::error_code ec;
  if (!std::filesystem::exists(path, ec)) throw FileError(name, 0, "no such file");
  if (std::filesystem::is_directory(path, ec)) throw FileError(name, 0, "is a directory, not a mesh file");
  std::ifstream in(path, std::ios::binary);
  if (!in) throw FileError(name, 0, "cannot open the file for reading");
  std::string data;
  in.seekg(0, std::ios::end);
  const auto size = in.tellg();
  if (size < 0) throw FileError(name, 0, "cannot determine the file size");
  data.resize(static_cast<std::size_t>(size));
  in.seekg(0, std::ios::beg);
  in.read(data.data(), static_cast<std::streamsize>(data.size()));
  if (!in) throw FileError(name, 0, "read error");
  return data;
}

std::string printable(std::string_view token) {
  constexpr std::size_t max_len = 40;
  std::string out;
  for (std::size_t i = 0; i < token.size() && i < max_len; ++i) {
    const auto c = static_cast<unsigned char>(token[i]);
    if (c >= 0x20 && c < 0x7f) {
      out += static_cast<char>(c);
    } else {
      static constexpr char hex[] = "0123456789abcdef";
      out += "\\x";
      out += hex[c >> 4];
      out += hex[c & 15];
    }
  }
  if (token.size() > max_len) out += "...";
  return out;
}

namespace {
bool is_space(char c) { return c == ' ' || c == '\t' || c == '\n' || c == '\r' || c == '\v' || c == '\f'; }
}  // namespace

void Cursor::skip_space() {
  while (pos_ < text_.size()) {
    const char c = text_[pos_];
    if (c == '\n') {
      ++line_;
      ++pos_;
    } else if (is_space(c)) {
      ++pos_;
    } else if (comment_ != '\0' && c == comment_) {
      while (pos_ < text_.size() && text_[pos_] != '\n') ++pos_;
    } else {
      break;
    }
  }
}

bool Cursor::at_end() {
  skip_space();
  return pos_ >= text_.size();
}

std::optional<std::string_view> Cursor::peek() {
  skip_space();
  if (pos_ >= text_.size()) return std::nullopt;
  std::size_t end = pos_;
  while (end < text_.size() && !is_space(text_[end]) && !(comment_ != '\0' && text_[end] == comment_)) ++end;
  return text_.substr(pos_, end - pos_);
}

std::optional<std::string_view> Cursor::peek_on_line() {
  std::size_t p = pos_;
  while (p < text_.size() && text_[p] != '\n' && is_space(text_[p])) ++p;
  if (p >= text_.size() || text_[p] == '\n' || (comment_ != '\0' && text_[p] == comment_)) return std::nullopt;
  std::size_t end = p;
  while (end < text_.size() && !is_space(text_[end])) ++end;
  return text_.substr(p, end - p);
}

std::string_view Cursor::token(std::string_view what) {
  const auto t = peek();
  token_line_ = line_;
  if (!t) fail_expected(what, "");
  pos_ += t->size();
  return *t;
}

void Cursor::expect(std::string_view word) {
  const std::string_view t = token(word);
  if (t != word) fail_expected(std::string("'") + std::string(word) + "'", t);
}

std::int64_t Cursor::integer(std::string_view what) {
  std::string_view t = token(what);
  std::string_view digits = t;
  if (digits.size() > 1 && digits[0] == '+') digits.remove_prefix(1);
  std::int64_t v = 0;
  const auto [end, ec] = std::from_chars(digits.data(), digits.data() + digits.size(), v);
  if (ec == std::errc::result_out_of_range)
    fail_semantic(std::string(what) + " '" + printable(t) + "' does not fit in a 64-bit integer", token_line_);
  if (ec != std::errc() || end != digits.data() + digits.size()) fail_expected(std::string(what) + " (an integer)", t);
  return v;
}

std::uint64_t Cursor::count(std::string_view what, std::uint64_t max) {
  const std::int64_t v = integer(what);
  if (v < 0) fail_expected(std::string(what) + " (a non-negative count)", std::to_string(v));
  if (static_cast<std::uint64_t>(v) > max)
    fail_semantic(std::string(what) + " is " + std::to_string(v) + ", more than the supported " + std::to_string(max),
                  token_line_);
  return static_cast<std::uint64_t>(v);
}

double Cursor::real(std::string_view what) {
  std::string_view t = token(what);
  std::string_view digits = t;
  if (digits.size() > 1 && digits[0] == '+' && digits[1] != '-' && digits[1] != '+') digits.remove_prefix(1);
  double v = 0;
  const auto [end, ec] = std::from_chars(digits.data(), digits.data() + digits.size(), v);
  if (end != digits.data() + digits.size() || (ec != std::errc() && ec != std::errc::result_out_of_range))
    fail_expected(std::string(what) + " (a real number)", t);
  if (ec == std::errc::result_out_of_range) {
    // from_chars reports both overflow and underflow this way: strtod tells them apart.
    const std::string copy(digits);
    v = std::strtod(copy.c_str(), nullptr);
    if (!std::isfinite(v)) return std::numeric_limits<double>::infinity();
  }
  return v;
}

std::string_view Cursor::rest_of_line() {
  std::size_t end = pos_;
  while (end < text_.size() && text_[end] != '\n') ++end;
  std::string_view s = text_.substr(pos_, end - pos_);
  if (!s.empty() && s.back() == '\r') s.remove_suffix(1);
  token_line_ = line_;
  pos_ = end;
  if (pos_ < text_.size()) {
    ++pos_;
    ++line_;
  }
  return s;
}

void Cursor::skip_line() { (void)rest_of_line(); }

void Cursor::end_line(std::string_view after) {
  while (pos_ < text_.size() && text_[pos_] != '\n' && is_space(text_[pos_])) ++pos_;
  if (pos_ >= text_.size()) return;
  if (text_[pos_] == '\n') {
    ++pos_;
    ++line_;
    return;
  }
  fail_expected_here("the end of the line after " + std::string(after));
}

std::string_view Cursor::raw(std::size_t n, std::string_view what) {
  if (n > remaining())
    throw ParseError(source_, 0,
                     std::string(what) + " (" + std::to_string(n) + " bytes of binary data at byte offset " +
                         std::to_string(pos_) + ")",
                     "only " + std::to_string(remaining()) + " bytes before the end of the file");
  const std::string_view s = text_.substr(pos_, n);
  pos_ += n;
  // so that lines of text after binary data are numbered as an editor shows them
  line_ += static_cast<std::size_t>(std::count(s.begin(), s.end(), '\n'));
  return s;
}

void Cursor::fail_expected(std::string_view what, std::string_view found) const {
  throw ParseError(source_, token_line_, std::string(what), printable(found));
}

void Cursor::fail_expected_here(std::string_view what) {
  const auto t = peek();
  token_line_ = line_;
  fail_expected(what, t ? *t : std::string_view{});
}

void Cursor::fail_semantic(const std::string& reason, std::size_t line) const {
  throw SemanticError(source_, line == 0 ? token_line_ : line, reason);
}

void Cursor::fail_unsupported(const std::string& reason, std::size_t line) const {
  throw UnsupportedError(source_, line == 0 ? token_line_ : line, reason);
}

}  // namespace sewn::io::detail
