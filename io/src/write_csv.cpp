#include <cerrno>
#include <cstring>
#include <stdexcept>

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
    : path_(path), columns_(std::move(columns)), out_(path, std::ios::binary | std::ios::trunc) {
  if (!out_) throw FileError(path_.string(), 0, std::string("cannot open for writing: ") + std::strerror(errno));
  if (columns_.empty()) throw std::invalid_argument("CsvWriter: needs at least one column");
  std::string line;
  for (std::size_t i = 0; i < columns_.size(); ++i) {
    if (i) line += ',';
    line += csv_field(columns_[i]);
  }
  out_ << line << '\n' << std::flush;
  if (!out_) throw FileError(path_.string(), 1, "write error");
}

void CsvWriter::row(std::span<const double> values) {
  if (values.size() != columns_.size())
    throw std::invalid_argument("CsvWriter::row: " + std::to_string(values.size()) + " values for " +
                                std::to_string(columns_.size()) + " columns in " + path_.string());
  std::string line;
  for (std::size_t i = 0; i < values.size(); ++i) {
    if (i) line += ',';
    line += format_double(values[i]);
  }
  out_ << line << '\n' << std::flush;  // a run that stops early still leaves every finished row
  if (!out_) throw FileError(path_.string(), 0, "write error (disk full?)");
}

}  // namespace sewn::io
