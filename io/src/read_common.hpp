#pragma once
// Internal helpers shared by the readers.

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdint>
#include <string>
#include <string_view>

#include "cursor.hpp"
#include "sewn/cmap/mesh.hpp"

namespace sewn::io::detail {

/// ASCII lower case: keywords and extensions are matched without regard to case.
inline std::string lower(std::string_view s) {
  std::string r(s);
  std::transform(r.begin(), r.end(), r.begin(), [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return r;
}

/// Reads `dim` coordinates (missing ones are 0) and rejects non-finite values, naming the node.
/// Source: a Cursor, or a reader of binary fields with the same real() and fail_semantic().
template <class Source>
Point3 read_point(Source& in, int dim, const std::string& node_name) {
  Point3 p{0.0, 0.0, 0.0};
  for (int k = 0; k < dim; ++k) {
    static constexpr const char* axis[3] = {"x", "y", "z"};
    p[static_cast<std::size_t>(k)] = in.real(std::string(axis[k]) + " coordinate of " + node_name);
    if (!std::isfinite(p[static_cast<std::size_t>(k)]))
      in.fail_semantic(node_name + " has a non-finite " + axis[k] + " coordinate");
  }
  return p;
}

/// Checks that an integer tag fits the mesh's 32-bit tags.
inline std::int32_t to_tag(const Cursor& in, std::int64_t v, const std::string& what) {
  if (v < INT32_MIN || v > INT32_MAX) in.fail_semantic(what + " " + std::to_string(v) + " does not fit in 32 bits");
  return static_cast<std::int32_t>(v);
}

}  // namespace sewn::io::detail
