#pragma once
// What every libFuzzer target here checks of a refusal, and how it reports a finding: a
// message on stderr and abort(), which libFuzzer records as a crash with the input.
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <string_view>
#include <vector>

#include "sewn/cmap/mesh.hpp"
#include "sewn/io/errors.hpp"

namespace sewn::fuzz {

[[noreturn]] inline void finding(const char* target, const char* what) {
  std::fprintf(stderr, "%s: %s\n", target, what);
  std::abort();
}

/// A refusal must name the source (first in what()) and give a reason.
inline void check_refusal(const char* target, const io::IoError& e, const std::string& source) {
  if (e.file() != source || e.reason().empty()) finding(target, "an IoError without its file or reason");
  if (std::string_view(e.what()).substr(0, source.size()) != source) finding(target, "what() does not start with the file");
}

/// What was read has only finite coordinates.
inline void check_finite(const char* target, const std::vector<Point3>& points) {
  for (const auto& p : points)
    for (const double x : p)
      if (!std::isfinite(x)) finding(target, "a point with a non-finite coordinate");
}

/// Reads, then checks what was read; an IoError on the way must be a proper refusal.
template <class Read, class Check>
void read_or_refusal(const char* target, const std::string& source, Read read, Check check) {
  try {
    check(read());
  } catch (const io::IoError& e) {
    check_refusal(target, e, source);
  }
}

}  // namespace sewn::fuzz
