#pragma once
// CMap: creation of isolated polygons, polylines and polyhedra. Included by cmap.hpp.

#include "sewn/cmap/mesh.hpp"

namespace sewn {

inline CellTemplate CellTemplate::from_faces(std::span<const std::span<const std::uint32_t>> faces) {
  constexpr std::uint32_t null = detail::null_index;
  if (faces.empty()) throw TopologyError("cmap::make_cell: empty face table");
  CellTemplate t;
  for (const auto& f : faces) {
    if (f.empty()) throw TopologyError("cmap::make_cell: a face has no vertex");
    t.face_size.push_back(static_cast<std::uint32_t>(f.size()));
    for (std::size_t k = 0; k < f.size(); ++k) {
      t.from.push_back(f[k]);
      t.to.push_back(f[(k + 1) % f.size()]);
    }
  }
  const std::size_t n = t.from.size();
  t.mate.assign(n, null);
  auto edge_name = [&](std::size_t k) {
    std::string name("(");  // appended piecewise: GCC 12 -O3 misreports "(" + string as overlapping (-Wrestrict)
    name.append(std::to_string(t.from[k])).append(", ").append(std::to_string(t.to[k])).append(")");
    return name;
  };
  if (faces.size() > 1) {
    for (std::size_t k = 0; k < n; ++k) {
      for (std::size_t l = 0; l < n; ++l) {
        if (l == k) continue;
        if (t.from[l] == t.from[k] && t.to[l] == t.to[k])
          throw TopologyError("cmap::make_cell: edge " + edge_name(k) +
                              " has the same direction in two faces (faces not consistently outward)");
        if (t.from[l] == t.to[k] && t.to[l] == t.from[k]) {
          if (t.mate[k] != null)
            throw TopologyError("cmap::make_cell: edge " + edge_name(k) + " is used by more than two faces");
          t.mate[k] = static_cast<std::uint32_t>(l);
        }
      }
      if (t.mate[k] == null)
        throw TopologyError("cmap::make_cell: edge " + edge_name(k) + " lies in a single face (the cell is not closed)");
    }
  }
  for (std::size_t k = 0; k < n; ++k)
    if (t.from[k] == 0 && t.to[k] == 1) {
      t.first = static_cast<std::uint32_t>(k);
      break;
    }
  return t;
}

template <int D, class... A>
Dart CMap<D, A...>::make_polygon(std::uint32_t n) {
  if (n == 0) throw TopologyError("cmap::make_polygon: a polygon needs at least one edge");
  const std::uint32_t first = new_dart();
  std::uint32_t prev = first;
  for (std::uint32_t k = 1; k < n; ++k) {
    const std::uint32_t x = new_dart();
    raw_link(prev, 1, x);
    prev = x;
  }
  raw_link(prev, 1, first);
  return Dart(first);
}

template <int D, class... A>
Dart CMap<D, A...>::make_polyline(std::uint32_t n) {
  if (n == 0) throw TopologyError("cmap::make_polyline: a polyline needs at least one edge");
  if constexpr (D == 1) {
    const std::uint32_t first = new_dart();
    std::uint32_t prev = first;
    for (std::uint32_t k = 1; k < n; ++k) {
      const std::uint32_t x = new_dart();
      raw_link(prev, 1, x);
      prev = x;
    }
    return Dart(first);
  } else {
    std::uint32_t first = detail::null_index, prev_fwd = detail::null_index, prev_bwd = detail::null_index;
    for (std::uint32_t k = 0; k < n; ++k) {
      const std::uint32_t fwd = new_dart(), bwd = new_dart();
      raw_link(fwd, 2, bwd);
      if (k == 0) {
        first = fwd;
      } else {
        raw_link(prev_fwd, 1, fwd);
        raw_link(bwd, 1, prev_bwd);
      }
      prev_fwd = fwd;
      prev_bwd = bwd;
    }
    return Dart(first);
  }
}

template <int D, class... A>
Dart CMap<D, A...>::make_cell(const CellTemplate& t, std::vector<Dart>* darts) {
  if (t.face_size.size() > 1 && D < 3) throw TopologyError("cmap::make_cell: a polyhedron needs D >= 3");
  // The new darts go straight into the caller's list (or a local one): builders call this once
  // per mesh cell, so no allocation per cell.
  std::vector<Dart> local;
  std::vector<Dart>& out = darts ? *darts : local;
  const std::size_t base = out.size();
  for (std::uint32_t size : t.face_size) {
    const std::uint32_t first = new_dart();
    out.push_back(Dart(first));
    std::uint32_t prev = first;
    for (std::uint32_t k = 1; k < size; ++k) {
      const std::uint32_t x = new_dart();
      out.push_back(Dart(x));
      raw_link(prev, 1, x);
      prev = x;
    }
    raw_link(prev, 1, first);
  }
  if (t.face_size.size() > 1)
    for (std::size_t k = 0; k < t.from.size(); ++k)
      if (k < t.mate[k]) raw_link(out[base + k].index(), 2, out[base + t.mate[k]].index());
  return out[base + t.first];
}

template <int D, class... A>
Dart CMap<D, A...>::make_cell(std::span<const std::span<const std::uint32_t>> faces, std::vector<Dart>* darts) {
  return make_cell(CellTemplate::from_faces(faces), darts);
}

template <int D, class... A>
Dart CMap<D, A...>::make_tetrahedron() {
  static_assert(D >= 3, "a tetrahedron needs D >= 3");
  static const CellTemplate t = CellTemplate::from_faces(cell_faces(CellType::tetrahedron));
  return make_cell(t);
}
template <int D, class... A>
Dart CMap<D, A...>::make_hexahedron() {
  static_assert(D >= 3, "a hexahedron needs D >= 3");
  static const CellTemplate t = CellTemplate::from_faces(cell_faces(CellType::hexahedron));
  return make_cell(t);
}
template <int D, class... A>
Dart CMap<D, A...>::make_prism() {
  static_assert(D >= 3, "a prism needs D >= 3");
  static const CellTemplate t = CellTemplate::from_faces(cell_faces(CellType::prism));
  return make_cell(t);
}
template <int D, class... A>
Dart CMap<D, A...>::make_pyramid() {
  static_assert(D >= 3, "a pyramid needs D >= 3");
  static const CellTemplate t = CellTemplate::from_faces(cell_faces(CellType::pyramid));
  return make_cell(t);
}

}  // namespace sewn
