#pragma once
// Numbers in error messages: 6 significant digits, shortest form (printf's %.6g), shared by every
// physics source so that messages read alike.
#include <cstdio>
#include <string>

namespace sewn::physics::detail {

inline std::string format_number(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.6g", v);
  return buf;
}

}  // namespace sewn::physics::detail
