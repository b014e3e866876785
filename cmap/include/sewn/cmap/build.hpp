#pragma once
// Building a map from an indexed mesh, and gluing cells that share a facet.
//
//   auto mesh = sewn::hex_grid(8, 8, 10);
//   sewn::CMap<3, NodeIndex> map;
//   auto built = sewn::build(map, mesh);            // creates and sews every cell
//   map.create_attributes<0>([&](sewn::Dart d) { return NodeIndex{built.vertex_of_dart[d.index()]}; });
//
// Every cell becomes its own closed piece of the map (volumes: polyhedra with outward faces;
// 2D cells: polygons; segments: a β2-linked dart pair, or one dart when D = 1). Then cells of the
// same dimension that share a facet are glued: volumes by β3 across shared faces, 2D cells by
// β2 across shared edges, segments by β1 at vertices with exactly two segments. A facet shared
// by three or more cells stays unsewn (its cells share mesh points only), which is how
// non-manifold junctions of mixed meshes are represented.
//
// sew_coincident_faces() does the gluing step alone on a map that already exists (cells made
// one by one, or pieces cut apart and to be put back): it sews the free facets that run through
// the same points.

#include <algorithm>
#include <array>
#include <span>
#include <string>
#include <vector>

#include "sewn/cmap/cmap.hpp"
#include "sewn/cmap/indexed_message.hpp"
#include "sewn/cmap/mesh.hpp"

namespace sewn {

struct BuildOptions {
  bool sew = true;                ///< glue cells that share a facet
  bool orient_surfaces = true;    ///< reverse 2D cells so that neighbours can be glued
  bool allow_nonmanifold = true;  ///< leave facets of 3+ cells unsewn (false: throw MeshError)
  bool manifold_volumes = false;  ///< throw MeshError for a face of 3+ volumes even if the above allows it (solids)
  std::string source = "mesh";    ///< name used in error messages (a file name, say)
};

struct BuildResult {
  /// Per mesh cell, one of its darts: for polyhedra the dart from local vertex 0 to 1 (VTK
  /// order), for polygons the dart starting at its first vertex, for segments the dart 0 -> 1.
  std::vector<Dart> cell_dart;
  /// Mesh point at which each dart starts, indexed by dart index (null_index for darts that
  /// existed before the build).
  std::vector<std::uint32_t> vertex_of_dart;
  /// Mesh cell each dart belongs to, indexed by dart index.
  std::vector<std::uint32_t> cell_of_dart;
  /// Per mesh cell: true if a 2D cell was reversed to orient its surface consistently.
  std::vector<bool> flipped;
  std::uint32_t sewn_facets = 0;        ///< facets glued
  std::uint32_t nonmanifold_facets = 0; ///< facets of 3+ cells left unsewn
  std::uint32_t unorientable_edges = 0; ///< edges of 2D cells left unsewn: orientations clash
};

namespace detail {

// A facet to be matched: its sorted points (up to 4) and the dart it starts from.
struct FacetKey {
  std::array<std::uint32_t, 4> v;
  std::uint8_t n;
  std::uint32_t dart;
  std::uint32_t cell;
  friend bool operator<(const FacetKey& a, const FacetKey& b) {
    return a.n != b.n ? a.n < b.n : a.v < b.v;
  }
};

// Groups items by their smallest point with a counting sort, then by `less` within a group:
// O(items + points). Calls f(first, last) for each run of items that `less` does not order
// (the same points). smallest(item) must lie in [0, num_points).
template <class T, class Smallest, class Less, class F>
void for_each_point_group(const std::vector<T>& items, std::uint32_t num_points, Smallest&& smallest, Less&& less, F&& f) {
  std::vector<std::uint32_t> start(std::size_t{num_points} + 1, 0);
  for (const T& k : items) ++start[smallest(k) + 1];
  for (std::uint32_t p = 0; p < num_points; ++p) start[p + 1] += start[p];
  std::vector<T> sorted(items.size());
  {
    std::vector<std::uint32_t> pos(start.begin(), start.end() - 1);
    for (const T& k : items) sorted[pos[smallest(k)]++] = k;
  }
  for (std::uint32_t p = 0; p < num_points; ++p) {
    auto first = sorted.begin() + start[p], last = sorted.begin() + start[p + 1];
    // groups hold the few items around one point: insertion sort beats std::sort here
    for (auto it = first + (first != last); it < last; ++it)
      for (auto j = it; j != first && less(*j, *(j - 1)); --j) std::iter_swap(j, j - 1);
    for (auto it = first; it != last;) {
      auto run = it + 1;
      while (run != last && !less(*it, *run)) ++run;
      f(it, run);
      it = run;
    }
  }
}

// for_each_point_group over facet keys, by their sorted points.
template <class F>
void for_each_facet_group(const std::vector<FacetKey>& facets, std::uint32_t num_points, F&& f) {
  for_each_point_group(
      facets, num_points, [](const FacetKey& k) { return k.v[0]; },
      [](const FacetKey& a, const FacetKey& b) { return a < b; }, std::forward<F>(f));
}

// Edge k of a 2D cell runs from its point k to point k+1.
struct CellEdge {
  std::uint32_t cell, k;
};
// The edges shared by 2D cells of a mesh, found once and used both to orient the cells and to
// sew them: pairs of cell edges through the same two points, and how many edges 3+ cells share.
struct SharedEdges {
  std::vector<std::pair<CellEdge, CellEdge>> pairs;
  std::uint32_t nonmanifold = 0;
  std::pair<std::uint32_t, std::uint32_t> first_nonmanifold{};  // two of its cells
};

inline SharedEdges shared_edges(const IndexedMesh& mesh) {
  std::vector<FacetKey> edges;
  for (std::uint32_t c = 0; c < mesh.num_cells(); ++c) {
    if (cell_dimension(mesh.types[c]) != 2) continue;
    const auto v = mesh.cell(c);
    for (std::uint32_t k = 0; k < v.size(); ++k) {
      const std::uint32_t a = v[k], b = v[(k + 1) % v.size()];
      edges.push_back({{std::min(a, b), std::max(a, b), 0, 0}, 2, k, c});
    }
  }
  SharedEdges out;
  for_each_facet_group(edges, mesh.num_points(), [&](auto first, auto last) {
    if (last - first == 2) {
      out.pairs.push_back({{first->cell, first->dart}, {(first + 1)->cell, (first + 1)->dart}});
    } else if (last - first > 2) {
      if (out.nonmanifold++ == 0) out.first_nonmanifold = {first->cell, (first + 1)->cell};
    }
  });
  return out;
}

}  // namespace detail

/// Creates the cells of `mesh` in `map` (which may already hold darts) and glues them as
/// described above. Throws MeshError naming the cell for an index out of range or a repeated
/// point in a cell, and MeshCellError (the cells apart, to be named as a file does) for a cell of
/// higher dimension than the map, two volumes whose shared face has the same orientation in both
/// (one is inverted), or a non-manifold facet when allow_nonmanifold is false (or, of volumes,
/// manifold_volumes is true). O(darts + points).
template <int D, class... A>
BuildResult build(CMap<D, A...>& map, const IndexedMesh& mesh, const BuildOptions& opt = {}) {
  constexpr std::uint32_t null = Dart::null_index;
  mesh.check_indices(opt.source);
  const std::uint32_t nc = mesh.num_cells();
  BuildResult res;
  res.cell_dart.resize(nc);
  res.flipped.assign(nc, false);

  // 1) sizes, dimension check
  std::uint64_t darts = 0;
  for (std::uint32_t c = 0; c < nc; ++c) {
    const CellType t = mesh.types[c];
    if (cell_dimension(t) > D)
      throw MeshCellError(opt.source, IndexedMessage() << CellRef{c} << " is a " + std::string(to_string(t)) +
                                                              " but the map has dimension " + std::to_string(D));
    if (cell_dimension(t) == 3)
      for (auto f : cell_faces(t)) darts += f.size();
    else if (cell_dimension(t) == 2)
      darts += static_cast<std::uint64_t>(cell_vertex_count(t));
    else
      darts += D == 1 ? 1 : 2;
  }
  map.reserve(static_cast<std::uint32_t>(map.dart_capacity() + darts));
  const std::uint32_t base = map.dart_capacity();
  res.vertex_of_dart.assign(base + darts, null);  // new darts reuse free slots or extend the range
  res.cell_of_dart.assign(base + darts, null);
  auto record = [&](Dart d, std::uint32_t point, std::uint32_t cell) {
    if (d.index() >= res.vertex_of_dart.size()) {
      res.vertex_of_dart.resize(d.index() + 1, null);
      res.cell_of_dart.resize(d.index() + 1, null);
    }
    res.vertex_of_dart[d.index()] = point;
    res.cell_of_dart[d.index()] = cell;
  };

  // 2) orient 2D cells: breadth-first over cells sharing a manifold edge, reversing a
  //    neighbour that runs along the shared edge in the same direction.
  // "cell 3 (tetrahedron) and cell 7 (tetrahedron)", its numbers kept apart
  auto two_cells = [&](std::uint32_t a, std::uint32_t b) {
    IndexedMessage m;
    m << CellRef{a} << " (" + std::string(to_string(mesh.types[a])) + ") and " << CellRef{b} << " (" + std::string(to_string(mesh.types[b])) + ")";
    return m;
  };
  const bool any_2d = std::any_of(mesh.types.begin(), mesh.types.end(), [](CellType t) { return cell_dimension(t) == 2; });
  const detail::SharedEdges shared = any_2d && (opt.orient_surfaces || (opt.sew && D >= 2)) ? detail::shared_edges(mesh) : detail::SharedEdges{};
  if (opt.sew && D >= 2 && shared.nonmanifold != 0 && !opt.allow_nonmanifold)
    throw MeshCellError(opt.source, IndexedMessage() << "3 or more cells share one edge, among them "
                                    << two_cells(shared.first_nonmanifold.first, shared.first_nonmanifold.second)
                                    << " (a non-manifold edge where a manifold is required)");
  auto same_direction = [&](const detail::CellEdge& e0, const detail::CellEdge& e1) {
    return mesh.cell(e0.cell)[e0.k] == mesh.cell(e1.cell)[e1.k];  // both start at the same point
  };
  if (opt.orient_surfaces && !shared.pairs.empty()) {
    // the pairs as adjacency lists (CSR), then a breadth-first walk per connected surface
    std::vector<std::uint32_t> first_nbr(std::size_t{nc} + 1, 0);
    for (const auto& [e0, e1] : shared.pairs) {
      ++first_nbr[e0.cell + 1];
      ++first_nbr[e1.cell + 1];
    }
    for (std::uint32_t c = 0; c < nc; ++c) first_nbr[c + 1] += first_nbr[c];
    std::vector<std::pair<std::uint32_t, bool>> nbr(first_nbr[nc]);  // (cell, same direction)
    {
      std::vector<std::uint32_t> pos(first_nbr.begin(), first_nbr.end() - 1);
      for (const auto& [e0, e1] : shared.pairs) {
        const bool same = same_direction(e0, e1);
        nbr[pos[e0.cell]++] = {e1.cell, same};
        nbr[pos[e1.cell]++] = {e0.cell, same};
      }
    }
    std::vector<std::uint8_t> seen(nc, 0);
    std::vector<std::uint32_t> queue;
    for (std::uint32_t c0 = 0; c0 < nc; ++c0) {
      if (cell_dimension(mesh.types[c0]) != 2 || seen[c0]) continue;
      seen[c0] = 1;
      queue.assign(1, c0);
      for (std::size_t h = 0; h < queue.size(); ++h) {
        const std::uint32_t c = queue[h];
        for (std::uint32_t i = first_nbr[c]; i < first_nbr[c + 1]; ++i) {
          const auto [o, same] = nbr[i];
          if (!seen[o]) {
            seen[o] = 1;
            res.flipped[o] = res.flipped[c] ^ same;
            queue.push_back(o);
          }
        }
      }
    }
  }

  // 3) create the cells, recording each dart's start point and cell
  std::array<CellTemplate, 7> templates;
  std::array<bool, 7> have_template{};
  std::vector<Dart> made;
  std::vector<detail::FacetKey> facets;      // faces of volumes
  std::vector<detail::FacetKey> segment_at;  // (point, dart ending there / starting there)
  for (std::uint32_t c = 0; c < nc; ++c) {
    const CellType t = mesh.types[c];
    const auto v = mesh.cell(c);
    const auto ti = static_cast<std::size_t>(t);
    made.clear();
    switch (cell_dimension(t)) {
      case 3: {
        if (!have_template[ti]) {
          templates[ti] = CellTemplate::from_faces(cell_faces(t));
          have_template[ti] = true;
        }
        const CellTemplate& tp = templates[ti];
        res.cell_dart[c] = map.make_cell(tp, &made);
        for (std::size_t h = 0; h < made.size(); ++h) record(made[h], v[tp.from[h]], c);
        std::size_t h = 0;
        for (std::uint32_t size : tp.face_size) {
          detail::FacetKey k{{0, 0, 0, 0}, static_cast<std::uint8_t>(size), made[h].index(), c};
          for (std::uint32_t l = 0; l < size; ++l) k.v[l] = v[tp.from[h + l]];
          for (std::uint32_t i = 1; i < size; ++i)  // at most 4 points: insertion sort
            for (std::uint32_t j = i; j > 0 && k.v[j] < k.v[j - 1]; --j) std::swap(k.v[j], k.v[j - 1]);
          for (std::uint32_t l = size; l < 4; ++l) k.v[l] = null;
          facets.push_back(k);
          h += size;
        }
        break;
      }
      case 2: {
        const auto n = static_cast<std::uint32_t>(v.size());
        const Dart first = map.make_polygon(n);
        res.cell_dart[c] = first;
        std::uint32_t x = first.index();
        for (std::uint32_t k = 0; k < n; ++k, x = map.b(x, 1)) {
          // a reversed cell walks its points backwards: dart k starts at v[(n - k) % n]
          const std::uint32_t p = res.flipped[c] ? v[(n - k) % n] : v[k];
          record(Dart(x), p, c);
        }
        break;
      }
      default: {
        if constexpr (D == 1) {
          const Dart d = map.create_dart();
          res.cell_dart[c] = d;
          record(d, v[0], c);
          segment_at.push_back({{v[1], 0, 0, 0}, 1, d.index(), c});  // ends at v[1]
          segment_at.push_back({{v[0], 0, 0, 0}, 1, d.index(), c});  // starts at v[0]
        } else {
          const Dart fwd = map.make_polyline(1);
          const Dart bwd = map.beta(fwd, 2);
          res.cell_dart[c] = fwd;
          record(fwd, v[0], c);
          record(bwd, v[1], c);
          segment_at.push_back({{v[1], 0, 0, 0}, 1, fwd.index(), c});
          segment_at.push_back({{v[0], 0, 0, 0}, 1, bwd.index(), c});
        }
      }
    }
  }
  if (!opt.sew) return res;

  // link_beta below marks the links unsound; every orbit it touches is complete on return.
  const bool links_sound = detail::LinkSoundness::get(map);
  // 4) glue facets shared by exactly two cells of the same dimension: 2D cells along edges
  //    (β2) if they run along them in opposite directions, volumes across faces (β3)
  auto start_of = [&](std::uint32_t x) { return res.vertex_of_dart[x]; };
  if constexpr (D >= 2) {
    res.nonmanifold_facets += shared.nonmanifold;
    // the dart of a 2D cell along its edge k: dart k, or dart n-1-k of a reversed cell
    auto dart_of = [&](const detail::CellEdge& e) {
      const auto n = static_cast<std::uint32_t>(mesh.cell(e.cell).size());
      std::uint32_t x = res.cell_dart[e.cell].index();
      for (std::uint32_t j = res.flipped[e.cell] ? n - 1 - e.k : e.k; j != 0; --j) x = map.b(x, 1);
      return x;
    };
    for (const auto& [e0, e1] : shared.pairs) {
      const std::uint32_t a = dart_of(e0), bb = dart_of(e1);
      if (start_of(a) == start_of(bb)) {
        ++res.unorientable_edges;
        continue;
      }
      map.template link_beta<2>(Dart(a), Dart(bb));
      ++res.sewn_facets;
    }
  }
  detail::for_each_facet_group(facets, mesh.num_points(), [&](auto first, auto last) {
    const auto count = last - first;
    if (count == 1) return;
    if (count > 2) {
      if (!opt.allow_nonmanifold || opt.manifold_volumes)
        throw MeshCellError(opt.source, IndexedMessage() << std::to_string(count) + " cells share one face, among them "
                                        << two_cells(first->cell, (first + 1)->cell)
                                        << " (a non-manifold face where a manifold is required)");
      ++res.nonmanifold_facets;
      return;
    }
    if constexpr (D >= 3) {
      // two faces: pair each dart u->v of one with the dart v->u of the other
      const std::uint32_t a = first->dart, bb = (first + 1)->dart;
      std::uint32_t y = bb;
      const std::uint32_t want = start_of(map.b(a, 1));
      std::uint32_t guard = 0;
      while (start_of(y) != want && guard++ < 4) y = map.b(y, 1);
      if (start_of(map.b(y, 1)) != start_of(a)) {
        throw MeshCellError(opt.source, two_cells(first->cell, (first + 1)->cell)
                                            << " share a face with the same orientation: both lie on the same side of it (they overlap), or one is inverted "
                                               "(negative volume)");
      }
      std::uint32_t x = a;
      do {
        map.template link_beta<3>(Dart(x), Dart(y));
        x = map.b(x, 1);
        y = map.b(y, 0);
      } while (x != a);
      ++res.sewn_facets;
    }
  });
  // 5) chain segments at points where exactly two of them meet
  detail::for_each_facet_group(segment_at, mesh.num_points(), [&](auto first, auto last) {
    if (last - first != 2) return;
    if constexpr (D == 1) {
      // one segment must end here and the other start here
      const bool starts0 = start_of(first->dart) == first->v[0];
      const bool starts1 = start_of((first + 1)->dart) == first->v[0];
      if (starts0 == starts1) {
        ++res.unorientable_edges;
        return;
      }
      const std::uint32_t in = starts0 ? (first + 1)->dart : first->dart;
      const std::uint32_t out = starts0 ? first->dart : (first + 1)->dart;
      map.template link_beta<1>(Dart(in), Dart(out));
    } else {
      // each entry is the dart of its segment ending at this point; its β2 starts here
      const std::uint32_t in0 = first->dart, in1 = (first + 1)->dart;
      map.template link_beta<1>(Dart(in0), Dart(map.b(in1, 2)));
      map.template link_beta<1>(Dart(in1), Dart(map.b(in0, 2)));
    }
    ++res.sewn_facets;
  });
  detail::LinkSoundness::restore(map, links_sound);
  return res;
}

struct SewCoincidentReport {
  std::uint32_t sewn = 0;         ///< facet pairs sewn
  std::uint32_t nonmanifold = 0;  ///< groups of 3+ free facets through the same points, left free
  std::uint32_t mismatched = 0;   ///< pairs left free: same orientation, or shapes sew<D> refuses
  friend bool operator==(const SewCoincidentReport&, const SewCoincidentReport&) = default;
};

/// Sews, by sew<D>, every two D-free facets of `map` (faces of a 3-map, edges of a 2-map) that
/// run through the same points in opposite directions; point_of(d) names the point dart d
/// starts at, in [0, num_points) (say, the value of its 0-attribute). Open facets (a β1 chain
/// that does not close) are skipped. Attributes merge as sew<D> merges them, on_merge included.
/// Throws TopologyError, the map unchanged, if point_of gives a point out of range.
/// O(free darts + num_points).
template <int D, class... A, class PointOf>
SewCoincidentReport sew_coincident_faces(CMap<D, A...>& map, PointOf&& point_of, std::uint32_t num_points) {
  static_assert(D == 2 || D == 3, "facets are glued by beta2 in a 2-map and by beta3 in a 3-map");
  constexpr std::uint32_t null = Dart::null_index;
  // 1) each free facet once (from its smallest dart): its darts' points, kept sorted in `pts`
  struct Facet {
    std::uint32_t dart, first, n;
  };
  std::vector<Facet> facets;
  std::vector<std::uint32_t> pts;
  auto start_of = [&](std::uint32_t x) {
    const std::uint32_t p = static_cast<std::uint32_t>(point_of(Dart(x)));
    if (p >= num_points)
      throw TopologyError("sew_coincident_faces: dart " + std::to_string(x) + " starts at point " + std::to_string(p) +
                          ", outside [0, " + std::to_string(num_points) + ")");
    return p;
  };
  for (Dart d : map.darts()) {
    const std::uint32_t x = d.index();
    if (map.b(x, D) != null) continue;
    const auto first = static_cast<std::uint32_t>(pts.size());
    if constexpr (D == 2) {
      const std::uint32_t y = map.b(x, 1);
      if (y == null) continue;
      const std::uint32_t p = start_of(x), q = start_of(y);
      pts.push_back(std::min(p, q));
      pts.push_back(std::max(p, q));
    } else {
      std::uint32_t y = x;
      bool smallest = true;
      do {
        smallest = smallest && y >= x;
        pts.push_back(start_of(y));
        y = map.b(y, 1);
      } while (y != null && y != x);
      if (y == null || !smallest) {  // open, or met from its smallest dart
        pts.resize(first);
        continue;
      }
      std::sort(pts.begin() + first, pts.end());
    }
    facets.push_back({x, first, static_cast<std::uint32_t>(pts.size()) - first});
  }
  // 2) group by the whole sorted point list
  auto key = [&](const Facet& f) { return std::span<const std::uint32_t>(pts.data() + f.first, f.n); };
  auto less = [&](const Facet& a, const Facet& b) {
    return a.n != b.n ? a.n < b.n : std::ranges::lexicographical_compare(key(a), key(b));
  };
  SewCoincidentReport rep;
  detail::for_each_point_group(facets, num_points, [&](const Facet& f) { return pts[f.first]; }, less, [&](auto it, auto run) {
    if (run - it > 2) {
      ++rep.nonmanifold;
    } else if (run - it == 2) {
      // pair dart a (u -> v) with the dart of the other facet that runs v -> u
      const std::uint32_t a = it->dart, want = start_of(map.b(a, 1));
      std::uint32_t y = (it + 1)->dart;
      if constexpr (D == 3)  // a face: find that dart on its cycle (an edge is its own dart)
        for (std::uint32_t k = 0; k < it->n && start_of(y) != want; ++k) y = map.b(y, 1);
      if (start_of(y) == want && start_of(map.b(y, 1)) == start_of(a) && map.template is_sewable<D>(Dart(a), Dart(y))) {
        map.template sew<D>(Dart(a), Dart(y));
        ++rep.sewn;
      } else {
        ++rep.mismatched;
      }
    }
  });
  return rep;
}

}  // namespace sewn
