#include <cerrno>
#include <cstring>
#include <stdexcept>

#include "sewn/io/atomic_file.hpp"
#include "sewn/io/write.hpp"

namespace sewn::io {

namespace {

// RFC 4180: a field with a comma, a quote or a line break is quoted, its quotes doubled.
std::string csv_field(const std::string& s) {
  if (s.find_first_of(",\"\r\n") == std::string::npos) return s;
  std::string r = "\"";
  for (char c : s) {
    if (c == '"') r += '"';
    r += c;
  }
  return r + "\"";
}

}  // namespace

CsvWriter::CsvWriter(const std::filesystem::path& path, std::vector<std::string> columns)
    : path_(path), columns_(std::move(columns)) {
  if (columns_.empty()) throw std::invalid_argument("CsvWriter: needs at least one column");
  for (std::size_t i = 0; i < columns_.size(); ++i) {
    if (i) content_ += ',';
    content_ += csv_field(columns_[i]);
  }
  content_ += '\n';
  flush();
}

CsvWriter::~CsvWriter() {
  try {
    flush();
  } catch (const std::exception&) {
    // already unwinding, or the caller did not flush: the file keeps its last complete version
  }
}

void CsvWriter::row(std::span<const double> values) {
  if (values.size() != columns_.size())
    throw std::invalid_argument("CsvWriter::row: " + std::to_string(values.size()) + " values for " +
                                std::to_string(columns_.size()) + " columns in " + path_.string());
  for (std::size_t i = 0; i < values.size(); ++i) {
    if (i) content_ += ',';
    content_ += format_double(values[i]);
  }
  content_ += '\n';
  // every row while the file is small; then at doubling sizes, so rewriting stays linear overall
  constexpr std::size_t small = 64 * 1024;
  if (content_.size() <= small || content_.size() >= 2 * written_) flush();
}

void CsvWriter::flush() {
  if (written_ == content_.size()) return;
  write_file_atomically(path_, content_);
  written_ = content_.size();
}

}  // namespace sewn::io
