#pragma once
// What every libFuzzer target here checks of a refusal, and how it reports a finding: a
// message on stderr and abort(), which libFuzzer records as a crash with the input.
#include <cstdio>
#include <cstdlib>
#include <string>
#include <string_view>

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

}  // namespace sewn::fuzz
