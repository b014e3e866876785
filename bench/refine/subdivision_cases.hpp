#pragma once
// The beams whose every hexahedron bench_refine subdivides 1:8, ours (refine.cpp) and CGAL's
// (cgal_subdivide.cpp): Table 1's coarse beam (2 hexahedra) and the finest uniform beam the
// scale steps (refined x3 at full scale: its subdivision is refined x4).
#include <cstdint>
#include <string>
#include <vector>

#include "sewn/cmap/mesh.hpp"
#include "sewn_bench.hpp"

namespace sewn::bench::refine_suite {

struct SubdivisionCase {
  std::string name;
  int refined = 0;  // the beam refined x this many times: 2^refined hexahedra per metre
};

inline std::vector<SubdivisionCase> subdivision_cases() {
  std::vector<SubdivisionCase> cases{{"all/coarse", 0}};
  if (scale() == Scale::small) cases.push_back({"all/refined x2", 2});
  if (scale() == Scale::full) cases.push_back({"all/refined x3", 3});
  return cases;
}

/// Table 1's beam, 2 m x 1 m x 1 m, as 2n x n x n cubes of side 1/n, n = 2^refined.
inline IndexedMesh beam_mesh(int refined) {
  const std::uint32_t n = 1u << refined;
  const double a = 1.0 / n;
  return hex_grid(2 * n, n, n, {{a, a, a}, {0, 0, 0}});
}

}  // namespace sewn::bench::refine_suite
