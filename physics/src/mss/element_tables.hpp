#pragma once
// Internal to physics/src/mss/: the local topology of each element kind (edges, diagonals,
// corners, the map template and the shortest dart paths to its corners), material checks, and
// the dart walks the model's building, queries and topology changes share.

#include <array>
#include <cstdint>
#include <cstdio>
#include <span>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "sewn/physics/errors.hpp"
#include "sewn/physics/mss_model.hpp"

namespace sewn::physics::mss_detail {


inline constexpr std::uint32_t no_cell = 0xffffffffu;

inline std::string sci(double x) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.3g", x);
  return buf;
}

using Edge = std::array<std::uint8_t, 2>;

// Local edges per kind, VTK vertex order. Hexahedra and quads list their edges axis by axis
// (the Baudet stiffness depends on the axis); tetrahedra and triangles follow van Gelder's order.
inline constexpr Edge hex_edges[12] = {{0, 1}, {3, 2}, {4, 5}, {7, 6}, {0, 3}, {1, 2}, {4, 7}, {5, 6}, {0, 4}, {1, 5}, {2, 6}, {3, 7}};
inline constexpr Edge tet_edges[6] = {{0, 1}, {0, 2}, {0, 3}, {1, 2}, {1, 3}, {2, 3}};
inline constexpr Edge quad_edges[4] = {{0, 1}, {3, 2}, {1, 2}, {0, 3}};
inline constexpr Edge tri_edges[3] = {{0, 1}, {1, 2}, {2, 0}};
inline constexpr Edge seg_edges[1] = {{0, 1}};
inline constexpr Edge hex_diagonals[4] = {{0, 6}, {1, 7}, {2, 4}, {3, 5}};
inline constexpr Edge quad_diagonals[2] = {{0, 2}, {1, 3}};

inline int corners(ElementKind k) {
  switch (k) {
    case ElementKind::hexahedron: return 8;
    case ElementKind::tetrahedron:
    case ElementKind::quad: return 4;
    case ElementKind::triangle: return 3;
    case ElementKind::segment: return 2;
  }
  return 0;
}

// Darts of an element starting at one of its corners: the faces meeting there in a polyhedron,
// one in a polygon or a segment. A vertex cell's mass sums ρ·measure/(corners·this) per dart.
inline int darts_per_corner(ElementKind k) {
  return k == ElementKind::hexahedron || k == ElementKind::tetrahedron ? 3 : 1;
}

// Grows a stamp vector to cover i and stamps it; false if already stamped this generation.
inline bool first_visit(std::vector<std::uint32_t>& stamp, std::size_t i, std::uint32_t generation) {
  if (i >= stamp.size()) stamp.resize(i + 1 + i / 2, 0);
  if (stamp[i] == generation) return false;
  stamp[i] = generation;
  return true;
}

inline std::span<const Edge> diagonals_of(ElementKind k) {
  if (k == ElementKind::hexahedron) return hex_diagonals;
  if (k == ElementKind::quad) return quad_diagonals;
  return {};
}

inline const CellTemplate& template_of(ElementKind k) {
  static const CellTemplate hex = CellTemplate::from_faces(cell_faces(CellType::hexahedron));
  static const CellTemplate tet = CellTemplate::from_faces(cell_faces(CellType::tetrahedron));
  return k == ElementKind::hexahedron ? hex : tet;
}

inline void check_material(const MaterialParams& m, std::size_t i) {
  const std::string name = "material " + std::to_string(i);
  auto positive = [&](double x, const char* what) {
    if (!(std::isfinite(x) && x > 0))
      throw InputError(name + ": " + what + " must be finite and > 0 (got " + std::to_string(x) + ")");
  };
  positive(m.young, "Young's modulus");
  positive(m.density, "density");
  positive(m.thickness, "thickness");
  positive(m.area, "cross-section area");
  if (!(m.poisson > -1 && m.poisson < 0.5))
    throw InputError(name + ": Poisson's ratio must be in (-1, 0.5) (got " + std::to_string(m.poisson) + ")");
}

// For each local vertex of a polyhedron, the shortest sequence of β1 / β2 steps from the
// canonical dart (the template's `first` half-edge) to a dart starting at that vertex: corners
// are then found in a few link reads instead of walking the whole volume.
using CornerPaths = std::array<std::vector<std::uint8_t>, 8>;
inline CornerPaths corner_paths(const CellTemplate& t) {
  const std::size_t n = t.from.size();
  std::vector<std::uint32_t> next(n), face_of(n);
  for (std::size_t h = 0, f = 0; f < t.face_size.size(); h += t.face_size[f], ++f)
    for (std::uint32_t k = 0; k < t.face_size[f]; ++k) next[h + k] = static_cast<std::uint32_t>(h + (k + 1) % t.face_size[f]);
  std::vector<std::vector<std::uint8_t>> path(n);
  std::vector<char> seen(n, 0);
  std::vector<std::uint32_t> queue{t.first};
  seen[t.first] = 1;
  for (std::size_t q = 0; q < queue.size(); ++q) {
    const std::uint32_t h = queue[q];
    for (auto [op, g] : {std::pair<std::uint8_t, std::uint32_t>{1, next[h]}, {2, t.mate[h]}}) {
      if (seen[g]) continue;
      seen[g] = 1;
      path[g] = path[h];
      path[g].push_back(op);
      queue.push_back(g);
    }
  }
  CornerPaths out;
  std::array<bool, 8> found{};
  for (std::uint32_t h : queue)  // breadth-first order: the first half-edge met per vertex is nearest
    if (!found[t.from[h]]) {
      found[t.from[h]] = true;
      out[t.from[h]] = path[h];
    }
  return out;
}

inline int local_edge_index(ElementKind k, std::uint8_t a, std::uint8_t b, std::span<const Edge> edges) {
  for (std::size_t e = 0; e < edges.size(); ++e)
    if ((edges[e][0] == a && edges[e][1] == b) || (edges[e][0] == b && edges[e][1] == a)) return static_cast<int>(e);
  (void)k;
  return -1;
}

}  // namespace sewn::physics::mss_detail

namespace sewn::physics {

template <int D>
template <class F>
void MssModel<D>::for_each_local_dart(const Element& el, F&& f) const {
  if (el.kind == ElementKind::hexahedron || el.kind == ElementKind::tetrahedron) {
    // Walk the cell's darts alongside its template: β1 follows the face ring, β2 the mate.
    const CellTemplate& t = mss_detail::template_of(el.kind);
    const std::size_t n = t.from.size();
    std::array<std::uint32_t, 24> face_start{}, face_end{};
    for (std::size_t h = 0, f0 = 0; f0 < t.face_size.size(); ++f0) {
      for (std::uint32_t k = 0; k < t.face_size[f0]; ++k) {
        face_start[h + k] = static_cast<std::uint32_t>(h);
        face_end[h + k] = static_cast<std::uint32_t>(h + t.face_size[f0]);
      }
      h += t.face_size[f0];
    }
    std::array<Dart, 24> dart_of_half{};
    std::array<std::uint32_t, 24> queue{};
    std::size_t qn = 0;
    dart_of_half[t.first] = el.dart;
    queue[qn++] = t.first;
    for (std::size_t qh = 0; qh < qn; ++qh) {
      const std::uint32_t h = queue[qh];
      const Dart x = dart_of_half[h];
      f(x, static_cast<std::uint8_t>(t.from[h]), static_cast<std::uint8_t>(t.to[h]));
      const std::uint32_t next = h + 1 == face_end[h] ? face_start[h] : h + 1;
      const std::uint32_t mate = t.mate[h];
      for (auto [hn, dn] : {std::pair{next, map_.beta(x, 1)}, std::pair{mate, map_.beta(x, 2)}}) {
        if (!dart_of_half[hn].is_null()) continue;
        dart_of_half[hn] = dn;
        queue[qn++] = hn;
      }
    }
    (void)n;
  } else if (el.kind == ElementKind::segment) {
    f(el.dart, std::uint8_t{0}, std::uint8_t{1});
    if constexpr (D >= 2)
      if (Dart back = map_.beta(el.dart, 2)) f(back, std::uint8_t{1}, std::uint8_t{0});
  } else {
    const auto n = static_cast<std::uint8_t>(mss_detail::corners(el.kind));
    Dart x = el.dart;
    for (std::uint8_t k = 0; k < n; ++k, x = map_.beta(x, 1)) {
      const auto from = static_cast<std::uint8_t>(el.reversed ? (n - k) % n : k);
      const auto to = static_cast<std::uint8_t>(el.reversed ? (2 * n - k - 1) % n : (k + 1) % n);
      f(x, from, to);
    }
  }
}


template <int D>
template <class F>
void MssModel<D>::for_each_edge_dart(std::uint32_t d, F&& f) const {
  // An edge's darts are linked by β2 and β3 only, which alternate along a path or a cycle:
  // walk it both ways from d, no marks needed.
  constexpr std::uint32_t null = Dart::null_index;
  f(d);
  int j = 2;
  std::uint32_t x = map_.b(d, j);
  for (; x != null && x != d; x = map_.b(x, j)) {
    f(x);
    if constexpr (D == 3) j = 5 - j;
  }
  if (x == d) return;  // a cycle
  if constexpr (D == 3)
    for (std::uint32_t y = map_.b(d, 3), jj = 2; y != null; y = map_.b(y, static_cast<int>(jj)), jj = 5 - jj) f(y);
}


}  // namespace sewn::physics
