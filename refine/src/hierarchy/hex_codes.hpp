#pragma once
// The per-dart codes of a hexahedron whose faces may be split (by its own refinement history or
// its neighbours'): found from rest geometry, since every particle a refinement makes lies at a
// multilinear interpolation of its element's corners.

#include <array>
#include <cstdint>

#include "hierarchy/model_access.hpp"
#include "hierarchy/segment_walk.hpp"

namespace sewn::refine::detail {

/// The model's hexahedron edges, as pairs of VTK corners.
inline constexpr std::array<std::array<std::uint8_t, 2>, 12> hex_edge_ends = {
    {{0, 1}, {3, 2}, {4, 5}, {7, 6}, {0, 3}, {1, 2}, {4, 7}, {5, 6}, {0, 4}, {1, 5}, {2, 6}, {3, 7}}};

/// The model's hexahedron diagonals, as pairs of VTK corners, in the order of Element::diagonal.
inline constexpr std::array<std::array<std::uint8_t, 2>, 4> hex_diagonal_ends = {{{0, 6}, {1, 7}, {2, 4}, {3, 5}}};

/// A point of a hexahedron's refinement lattice: each coordinate 0, 1 or 2 (halves of the parent).
using Lat = std::array<int, 3>;
/// VTK corner order in lattice coordinates of the parent.
inline constexpr std::array<Lat, 8> corner_lattice = {{{0, 0, 0}, {2, 0, 0}, {2, 2, 0}, {0, 2, 0}, {0, 0, 2}, {2, 0, 2}, {2, 2, 2}, {0, 2, 2}}};
/// The lattice point's index among the 27.
constexpr int at(const Lat& p) { return p[0] + 3 * p[1] + 9 * p[2]; }

/// Where the rest point r lies on the segment [a, b]: its parameter, or -1 if off the segment.
inline double on_segment(const Eigen::Vector3d& r, const Eigen::Vector3d& a, const Eigen::Vector3d& b) {
  const Eigen::Vector3d u = b - a, w = r - a;
  const double l2 = u.squaredNorm(), t = w.dot(u) / l2;
  if (t < -1e-9 || t > 1 + 1e-9 || (w - t * u).squaredNorm() > 1e-18 * l2) return -1;
  return t;
}

/// Codes every dart of a hexahedron's volume: its corner (or none), and the element edge it lies
/// on, flagged on the dart running from the lower to the higher local vertex (MssModel's
/// convention); a dart inside a face (a finer neighbour's) lies on no edge. Every vertex of the
/// volume is marked for the model's resync.
inline void code_hex_volume(physics::MssModel<3>& m, const DartList& vol, const std::array<physics::Index, 8>& corner) {
  using A = ModelAccess<3>;
  // the 12 edges' ends at rest, read once for all the volume's darts (as on_segment reads them)
  std::array<Eigen::Vector3d, 12> ra, rb;
  for (std::size_t k = 0; k < 12; ++k) {
    ra[k] = m.rest_position(corner[hex_edge_ends[k][0]]);
    rb[k] = m.rest_position(corner[hex_edge_ends[k][1]]);
  }
  for (Dart x : vol) {
    const physics::Index s = m.node_of(x), t = end_node(m, x);
    std::uint8_t vertex = physics::not_a_corner, code = 0;
    for (std::size_t w = 0; w < 8; ++w)
      if (corner[w] == s) vertex = static_cast<std::uint8_t>(w);
    const Eigen::Vector3d rs = m.rest_position(s), rt = m.rest_position(t);
    for (std::size_t k = 0; k < 12; ++k) {
      const auto [a, b] = hex_edge_ends[k];
      const double ts = on_segment(rs, ra[k], rb[k]);
      if (ts < 0) continue;
      const double tt = on_segment(rt, ra[k], rb[k]);
      if (tt < 0) continue;
      code = static_cast<std::uint8_t>(k | ((tt > ts) == (a < b) ? 0x80 : 0));
      break;
    }
    A::set_codes(m, x, vertex, code);
    A::mark_vertex_dirty(m, x);
  }
}

}  // namespace sewn::refine::detail
