#include "sewn/io/cleanup.hpp"

#include <algorithm>
#include <array>

namespace sewn::io {

namespace {

using Key = std::array<std::uint32_t, 4>;  // sorted point indices, padded with 0xffffffff

constexpr std::uint32_t none = 0xffffffffu;

template <class It>
Key key_of(It first, It last) {
  Key k{none, none, none, none};
  std::copy(first, last, k.begin());
  std::sort(k.begin(), k.end());
  return k;
}

}  // namespace

std::vector<bool> embedded_cells(const IndexedMesh& mesh) {
  std::vector<Key> faces, edges;  // faces of volumes; edges of volumes and 2D cells
  for (std::uint32_t c = 0; c < mesh.num_cells(); ++c) {
    const auto v = mesh.cell(c);
    const CellType t = mesh.types[c];
    if (cell_dimension(t) == 3) {
      for (auto f : cell_faces(t)) {
        std::array<std::uint32_t, 4> p{};
        for (std::size_t k = 0; k < f.size(); ++k) p[k] = v[f[k]];
        faces.push_back(key_of(p.begin(), p.begin() + static_cast<std::ptrdiff_t>(f.size())));
        for (std::size_t k = 0; k < f.size(); ++k) {
          const std::array<std::uint32_t, 2> e{p[k], p[(k + 1) % f.size()]};
          edges.push_back(key_of(e.begin(), e.end()));
        }
      }
    } else if (cell_dimension(t) == 2) {
      for (std::size_t k = 0; k < v.size(); ++k) {
        const std::array<std::uint32_t, 2> e{v[k], v[(k + 1) % v.size()]};
        edges.push_back(key_of(e.begin(), e.end()));
      }
    }
  }
  std::sort(faces.begin(), faces.end());
  std::sort(edges.begin(), edges.end());
  std::vector<bool> embedded(mesh.num_cells(), false);
  for (std::uint32_t c = 0; c < mesh.num_cells(); ++c) {
    const auto v = mesh.cell(c);
    const int dim = cell_dimension(mesh.types[c]);
    if (dim == 3) continue;  // volumes are never embedded, and have more points than a key holds
    const Key k = key_of(v.begin(), v.end());
    const auto& pool = dim == 2 ? faces : edges;
    embedded[c] = std::binary_search(pool.begin(), pool.end(), k);
  }
  return embedded;
}

std::size_t drop_embedded_cells(IndexedMesh& mesh) {
  const std::vector<bool> embedded = embedded_cells(mesh);
  IndexedMesh kept;
  kept.points = std::move(mesh.points);
  std::size_t removed = 0;
  for (std::uint32_t c = 0; c < mesh.num_cells(); ++c) {
    if (embedded[c]) {
      ++removed;
      continue;
    }
    kept.add_cell(mesh.types[c], mesh.cell(c), mesh.tags[c]);
  }
  mesh = std::move(kept);
  return removed;
}

std::vector<std::uint32_t> drop_unused_points(IndexedMesh& mesh) {
  std::vector<std::uint32_t> map(mesh.num_points(), none);
  for (std::uint32_t p : mesh.conn) map[p] = 0;
  std::vector<Point3> points;
  for (std::uint32_t p = 0; p < mesh.num_points(); ++p) {
    if (map[p] == none) continue;
    map[p] = static_cast<std::uint32_t>(points.size());
    points.push_back(mesh.points[p]);
  }
  for (auto& p : mesh.conn) p = map[p];
  mesh.points = std::move(points);
  return map;
}

}  // namespace sewn::io
