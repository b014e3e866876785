#pragma once
// The cell complex of a map as flat arrays, shared by the homology, orientation, boundary and
// link computations of topology.hpp. Internal to sewn_cmap.

#include <array>
#include <cstdint>
#include <vector>

#include "sewn/cmap/topology.hpp"

namespace sewn::topo {

inline constexpr std::uint32_t null = Dart::null_index;

/// Compressed rows: the entries of row r are idx[start[r] .. start[r+1]).
struct Csr {
  std::vector<std::uint32_t> start{0};
  std::vector<std::uint32_t> idx;
  [[nodiscard]] std::uint32_t rows() const { return static_cast<std::uint32_t>(start.size() - 1); }
  [[nodiscard]] std::uint32_t size(std::uint32_t r) const { return start[r + 1] - start[r]; }
  [[nodiscard]] const std::uint32_t* begin(std::uint32_t r) const { return idx.data() + start[r]; }
  [[nodiscard]] const std::uint32_t* end(std::uint32_t r) const { return idx.data() + start[r + 1]; }
  /// Groups items 0..n-1 by key(item) ∈ [0, rows) (counting sort, stable). O(n + rows).
  template <class Key>
  static Csr group(std::uint32_t rows, std::uint32_t n, Key&& key) {
    Csr c;
    c.start.assign(std::size_t{rows} + 1, 0);
    for (std::uint32_t i = 0; i < n; ++i)
      if (const std::uint32_t k = key(i); k != null) ++c.start[k + 1];
    for (std::uint32_t r = 0; r < rows; ++r) c.start[r + 1] += c.start[r];
    c.idx.resize(c.start[rows]);
    std::vector<std::uint32_t> pos(c.start.begin(), c.start.end() - 1);
    for (std::uint32_t i = 0; i < n; ++i)
      if (const std::uint32_t k = key(i); k != null) c.idx[pos[k]++] = i;
    return c;
  }
};

/// A top cell seen across one of its facets: a dart of 2-map, a β1 cycle of a 3-map.
struct Incidence {
  std::uint32_t top, facet, dart;
  std::int8_t sign;  ///< +1 if the top cell's darts run along the facet's reference orientation
};

struct Complex {
  int dim = 0;
  bool by_points = false;
  const std::vector<std::array<std::uint32_t, 4>>* beta = nullptr;
  std::uint32_t cap = 0;
  std::array<std::uint32_t, 4> count{};
  std::array<std::vector<std::uint32_t>, 4> cell;  ///< per dimension, the cell of each dart
  std::array<std::vector<std::uint32_t>, 4> root;  ///< per dimension, the smallest dart of each cell
  std::vector<std::uint8_t> edge_rev;  ///< 1 if the dart runs against its edge's reference direction
  std::vector<std::uint8_t> face_rev;  ///< 3-maps: 1 if its β1 cycle runs against its face's reference
  std::vector<Incidence> incidences;   ///< every top cell across every facet, by dart
  Csr by_facet;                        ///< incidences grouped by facet

  [[nodiscard]] std::uint32_t b(std::uint32_t x, int i) const { return (*beta)[x][static_cast<std::size_t>(i)]; }
  [[nodiscard]] bool alive(std::uint32_t x) const { return (*beta)[x][0] != detail::dead_marker; }
  /// Key of the end of x's edge at which x starts (2·edge + 0 at its reference start, + 1 at its end).
  [[nodiscard]] std::uint32_t start_key(std::uint32_t x) const { return 2 * cell[1][x] + edge_rev[x]; }
  /// Key of the end of x's edge at which x ends.
  [[nodiscard]] std::uint32_t end_key(std::uint32_t x) const { return 2 * cell[1][x] + (1u - edge_rev[x]); }
};

/// Builds the complex; throws TopologyError for open faces or volumes, or inconsistent points.
Complex build_complex(const detail::TopologyInput& in, std::span<const std::uint32_t> point_of_dart);

/// Fills out.components (cells, Betti numbers, χ, a dart) and out.total; returns the component
/// of each vertex (components numbered in order of their smallest dart).
std::vector<std::uint32_t> compute_homology(const Complex& c, Topology& out);

/// Orientation of top cells, boundary components, links of vertices and edges.
void compute_orientation(const Complex& c, const std::vector<std::uint32_t>& comp_of_vertex, Topology& out);
void compute_boundary(const Complex& c, const std::vector<std::uint32_t>& comp_of_vertex, Topology& out);
void compute_manifoldness(const Complex& c, Topology& out);

/// Union-find with path halving and union by size.
class UnionFind {
 public:
  explicit UnionFind(std::uint32_t n) : parent_(n), size_(n, 1) {
    for (std::uint32_t i = 0; i < n; ++i) parent_[i] = i;
  }
  std::uint32_t find(std::uint32_t x) {
    while (parent_[x] != x) {
      parent_[x] = parent_[parent_[x]];
      x = parent_[x];
    }
    return x;
  }
  /// True if a and b were in different sets.
  bool unite(std::uint32_t a, std::uint32_t b) {
    a = find(a);
    b = find(b);
    if (a == b) return false;
    if (size_[a] < size_[b]) std::swap(a, b);
    parent_[b] = a;
    size_[a] += size_[b];
    return true;
  }

 private:
  std::vector<std::uint32_t> parent_, size_;
};

}  // namespace sewn::topo
