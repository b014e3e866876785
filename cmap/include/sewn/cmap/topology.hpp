#pragma once
// Topology invariants of a 2- or 3-map: Betti numbers over Z/2, orientability (and an
// orientation), the boundary with its components and their genus, and manifoldness of every
// vertex and edge, for the whole map and for each connected component.
//
//   sewn::Topology t = sewn::topology(map);                 // the map's own cell complex
//   sewn::Topology q = sewn::topology(map, {built.vertex_of_dart});  // cells identified by points
//
// The cell complex of a map. Its i-cells are the map's i-orbits (cmap.hpp). The boundary of an
// i-cell is read from one copy of the cell with its own darts: an edge is one dart, from its
// start vertex to its end vertex (the start of β1); a face is one β1 cycle, whose boundary is
// the edges of its darts; a volume of a 3-map is its ⟨β1, β2⟩ orbit, whose boundary is the
// faces of its β1 cycles. Each (i-1)-cell is counted as many times as it occurs, mod 2: a cell
// glued to itself (an edge 2-sewn to another dart of the same face, a face 3-sewn to its own
// volume, a loop edge) cancels out of the boundary, as it does in cellular homology over Z/2.
// This is a chain complex (∂∂ = 0) when every face is a closed β1 cycle and, in a 3-map, every
// volume is closed (no 2-free dart): topology() checks both and throws TopologyError naming the
// first dart that breaks them.
//
// A combinatorial map is orientable by construction: every dart of a cell runs against its
// βi partner, so the map's own complex always is (each top cell keeps the orientation of its
// darts). A Möbius strip or Klein bottle exists only once faces are identified by their
// points: builders leave unsewn the edges along which two faces run the same way
// (BuildResult::unorientable_edges) and the facets of three or more cells. Given the point at
// which each dart starts (`point_of_dart`, e.g. BuildResult::vertex_of_dart), topology()
// computes every invariant on the quotient complex: vertices are points, edges are point
// pairs, faces of a 3-map are point sets (the top cells, faces of a 2-map or volumes of a
// 3-map, are never identified). That is the complex of the mesh the map was built from.
//
// Cost: O(n) for the complex (n = dart capacity; O(n log n) with points, for the hashing of
// keys), O(n α(n)) for b0 and b_D (union-find over the 1-skeleton and over the top cells across
// their facets), and for b1 and b2 of a 3-map a sparse reduction of ∂2 over GF(2): the rows of
// a spanning forest of the 1-skeleton and the columns of a spanning forest of the dual graph are
// dropped first (they carry no rank: the clearing / twist optimisation, with the pivots given by
// the forests), then columns and rows with a single entry are eliminated (elementary collapses),
// then what is left is reduced column by column (each column a sorted list of rows, a pivot
// table by lowest row): O(cells · fill), where fill is the length of the columns reduced last
// (zero on the meshes of bench/cmap, all of which the collapses finish). When some facet has
// three or more top cells, b_D comes from the reduction of ∂_D instead, whose pivots clear ∂_{D-1}.
// Orientability, boundary and manifoldness are O(n log n) (links are sorted per vertex). Memory:
// about 60 bytes per dart. Does not change the map; uses no mark.

#include <array>
#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include "sewn/cmap/cmap.hpp"

namespace sewn {

struct TopologyOptions {
  /// Point at which each dart starts, indexed by dart index (BuildResult::vertex_of_dart); empty
  /// for the map's own complex. Darts of one vertex must share a point, and an edge must join
  /// two different points (a TopologyError names the dart otherwise).
  std::span<const std::uint32_t> point_of_dart{};
  /// Compute vertex and edge links (manifoldness); the most expensive part after homology.
  bool manifoldness = true;
};

/// Counts and Betti numbers over Z/2 of one connected component (or of the whole map).
struct ComponentTopology {
  std::array<std::int64_t, 4> cells{};  ///< number of i-cells, i = 0..D (0 past D)
  std::array<std::int64_t, 4> betti{};  ///< b0..bD over Z/2 (0 past D)
  std::int64_t euler = 0;               ///< Σ (-1)^i cells[i] = Σ (-1)^i betti[i]
  bool orientable = true;               ///< see Topology::orientable
  std::uint32_t boundary_components = 0;
  /// Surfaces (D = 2): the genus, from χ = 2 - 2g - b (orientable) or χ = 2 - g - b (the number
  /// of cross-caps, non-orientable). -1 for a 3-map (see BoundaryComponent::genus).
  std::int64_t genus = -1;
  Dart dart;  ///< a dart of the component (its smallest)
};

/// One connected piece of the boundary: the facets that lie in a single top cell, joined when
/// they share a vertex (so two boundary surfaces touching at a point count as one piece).
struct BoundaryComponent {
  std::uint32_t component = 0;          ///< index in Topology::components
  std::array<std::int64_t, 3> cells{};  ///< vertices, edges, faces (faces: 0 for a 2-map)
  std::int64_t euler = 0;
  bool orientable = true;
  /// 3-map: true if the piece is a closed surface (every edge in two of its faces, the face
  /// corners around every vertex one cycle). 2-map: false (a boundary curve).
  bool surface = false;
  /// The genus of a closed surface (2 - χ)/2, or its number of cross-caps 2 - χ when
  /// non-orientable; -1 when the piece is not a closed surface (pinched) or is a curve.
  std::int64_t genus = -1;
  Dart dart;  ///< a dart of one of its facets (the side inside the top cell)
};

/// A vertex or edge whose link is neither a sphere nor a disc.
struct NonManifoldCell {
  int dim = 0;             ///< 0: vertex, 1: edge
  std::uint32_t cell = 0;  ///< index of the cell (in the order of Topology::cell_of_dart)
  Dart dart;               ///< a dart of it
  std::string why;         ///< what the link is ("2 pieces", "an edge in 3 faces", ...)
};

struct Topology {
  int dim = 0;
  ComponentTopology total;                     ///< the whole map
  std::vector<ComponentTopology> components;   ///< in order of their smallest dart
  /// True if the top cells (faces of a 2-map, volumes of a 3-map) can be given orientations
  /// such that every facet of exactly two top cells gets opposite orientations from them.
  /// Facets of three or more top cells are non-manifold (reported below) and not constrained.
  bool orientable = true;
  /// Per top cell: +1 keep the orientation of its darts, -1 reverse it; a consistent orientation
  /// of each orientable component (every cell of a non-orientable component: 0).
  std::vector<std::int8_t> orientation;
  /// Per dimension i = 0..D, the i-cell of each dart (index by dart index; null_index for dead
  /// darts), cells numbered in order of their smallest dart.
  std::array<std::vector<std::uint32_t>, 4> cell_of_dart;
  std::vector<std::uint32_t> component_of_dart;
  std::vector<BoundaryComponent> boundary;
  std::vector<NonManifoldCell> nonmanifold;  ///< vertices first, then edges
  bool manifoldness_checked = false;
};

namespace detail {
// The β links of a map, copied so the invariants are computed by non-template code: β0..β3 per
// dart index (null past D), and dead darts with β0 = dead_marker.
struct TopologyInput {
  int dim = 0;
  std::vector<std::array<std::uint32_t, 4>> beta;
};
Topology compute_topology(const TopologyInput& in, const TopologyOptions& opt);
}  // namespace detail

/// Every invariant above. Throws TopologyError if D is not 2 or 3, if a face is open (a 1-free
/// dart), if a volume of a 3-map is open (a 2-free dart), or if point_of_dart is inconsistent.
/// O(n log n) time, O(n) memory (see the top of this header).
template <int D, class... A>
Topology topology(const CMap<D, A...>& map, const TopologyOptions& opt = {}) {
  static_assert(D == 2 || D == 3, "topology invariants are computed for 2- and 3-maps");
  detail::TopologyInput in;
  in.dim = D;
  const std::uint32_t n = map.dart_capacity();
  in.beta.resize(n);
  for (std::uint32_t x = 0; x < n; ++x) {
    auto& r = in.beta[x];
    r.fill(Dart::null_index);
    if (!map.is_alive(Dart(x))) {
      r[0] = detail::dead_marker;
      continue;
    }
    for (int i = 0; i <= D; ++i) r[static_cast<std::size_t>(i)] = map.b(x, i);
  }
  return detail::compute_topology(in, opt);
}

}  // namespace sewn
