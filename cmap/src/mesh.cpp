#include "sewn/cmap/mesh.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <numbers>

#include "sewn/cmap/errors.hpp"

namespace sewn {

namespace {

// Outward faces, VTK vertex order (see mesh.hpp).
constexpr std::uint32_t tet_f[4][3] = {{0, 2, 1}, {0, 1, 3}, {1, 2, 3}, {2, 0, 3}};
constexpr std::uint32_t hex_f[6][4] = {{0, 3, 2, 1}, {4, 5, 6, 7}, {0, 1, 5, 4},
                                       {1, 2, 6, 5}, {2, 3, 7, 6}, {3, 0, 4, 7}};
constexpr std::uint32_t prism_tri[2][3] = {{0, 1, 2}, {3, 5, 4}};
constexpr std::uint32_t prism_quad[3][4] = {{0, 3, 4, 1}, {1, 4, 5, 2}, {2, 5, 3, 0}};
constexpr std::uint32_t pyr_base[4] = {0, 3, 2, 1};
constexpr std::uint32_t pyr_tri[4][3] = {{0, 1, 4}, {1, 2, 4}, {2, 3, 4}, {3, 0, 4}};

const std::array<std::span<const std::uint32_t>, 4> tet_faces{tet_f[0], tet_f[1], tet_f[2], tet_f[3]};
const std::array<std::span<const std::uint32_t>, 6> hex_faces{hex_f[0], hex_f[1], hex_f[2],
                                                              hex_f[3], hex_f[4], hex_f[5]};
const std::array<std::span<const std::uint32_t>, 5> prism_faces{prism_tri[0], prism_tri[1], prism_quad[0],
                                                                prism_quad[1], prism_quad[2]};
const std::array<std::span<const std::uint32_t>, 5> pyramid_faces{pyr_base, pyr_tri[0], pyr_tri[1], pyr_tri[2],
                                                                  pyr_tri[3]};

Point3 grid_point(const GridSpec& g, std::uint32_t i, std::uint32_t j, std::uint32_t k) {
  return {g.origin[0] + i * g.spacing[0], g.origin[1] + j * g.spacing[1], g.origin[2] + k * g.spacing[2]};
}

void check_grid(std::uint32_t nx, std::uint32_t ny, std::uint32_t nz, const GridSpec& g, const char* what) {
  if (nx == 0 || ny == 0 || nz == 0)
    throw MeshError(std::string(what) + ": every cell count must be at least 1");
  for (double s : g.spacing)
    if (!(s > 0.0)) throw MeshError(std::string(what) + ": every spacing must be positive and finite");
}

}  // namespace

const char* to_string(CellType t) {
  switch (t) {
    case CellType::segment: return "segment";
    case CellType::triangle: return "triangle";
    case CellType::quad: return "quad";
    case CellType::tetrahedron: return "tetrahedron";
    case CellType::hexahedron: return "hexahedron";
    case CellType::prism: return "prism";
    case CellType::pyramid: return "pyramid";
  }
  return "?";
}

std::span<const std::span<const std::uint32_t>> cell_faces(CellType t) {
  switch (t) {
    case CellType::tetrahedron: return tet_faces;
    case CellType::hexahedron: return hex_faces;
    case CellType::prism: return prism_faces;
    case CellType::pyramid: return pyramid_faces;
    default: return {};
  }
}

std::uint32_t IndexedMesh::add_cell(CellType t, std::span<const std::uint32_t> vertices, std::int32_t tag) {
  if (static_cast<int>(vertices.size()) != cell_vertex_count(t))
    throw MeshError(std::string("a ") + to_string(t) + " needs " + std::to_string(cell_vertex_count(t)) +
                    " vertices, got " + std::to_string(vertices.size()));
  types.push_back(t);
  conn.insert(conn.end(), vertices.begin(), vertices.end());
  offsets.push_back(static_cast<std::uint32_t>(conn.size()));
  tags.push_back(tag);
  return static_cast<std::uint32_t>(types.size() - 1);
}

std::array<std::uint32_t, 4> IndexedMesh::count_by_dimension() const {
  std::array<std::uint32_t, 4> n{};
  for (CellType t : types) ++n[static_cast<std::size_t>(cell_dimension(t))];
  return n;
}

void IndexedMesh::check_indices(const std::string& source) const {
  if (offsets.size() != types.size() + 1 || tags.size() != types.size() || offsets.back() != conn.size())
    throw MeshError(source + ": cell arrays have inconsistent sizes");
  for (std::uint32_t c = 0; c < num_cells(); ++c) {
    const auto v = cell(c);
    for (std::size_t k = 0; k < v.size(); ++k) {
      if (v[k] >= points.size())
        throw MeshError(source + ": cell " + std::to_string(c) + " (" + to_string(types[c]) + ") refers to point " +
                        std::to_string(v[k]) + " but there are only " + std::to_string(points.size()) + " points");
      for (std::size_t l = 0; l < k; ++l)
        if (v[l] == v[k])
          throw MeshError(source + ": cell " + std::to_string(c) + " (" + to_string(types[c]) +
                          ") uses point " + std::to_string(v[k]) + " twice");
    }
  }
}

IndexedMesh hex_grid(std::uint32_t nx, std::uint32_t ny, std::uint32_t nz, const GridSpec& g) {
  check_grid(nx, ny, nz, g, "hex_grid");
  IndexedMesh m;
  const std::uint32_t px = nx + 1, py = ny + 1;
  m.points.reserve(static_cast<std::size_t>(px) * py * (nz + 1));
  for (std::uint32_t k = 0; k <= nz; ++k)
    for (std::uint32_t j = 0; j <= ny; ++j)
      for (std::uint32_t i = 0; i <= nx; ++i) m.points.push_back(grid_point(g, i, j, k));
  auto id = [&](std::uint32_t i, std::uint32_t j, std::uint32_t k) { return i + px * (j + py * k); };
  m.types.reserve(static_cast<std::size_t>(nx) * ny * nz);
  m.conn.reserve(8 * static_cast<std::size_t>(nx) * ny * nz);
  for (std::uint32_t k = 0; k < nz; ++k)
    for (std::uint32_t j = 0; j < ny; ++j)
      for (std::uint32_t i = 0; i < nx; ++i)
        m.add_cell(CellType::hexahedron, {id(i, j, k), id(i + 1, j, k), id(i + 1, j + 1, k), id(i, j + 1, k),
                                          id(i, j, k + 1), id(i + 1, j, k + 1), id(i + 1, j + 1, k + 1),
                                          id(i, j + 1, k + 1)});
  return m;
}

IndexedMesh tet_grid(std::uint32_t nx, std::uint32_t ny, std::uint32_t nz, TetSplit split, const GridSpec& g) {
  IndexedMesh hex = hex_grid(nx, ny, nz, g);
  IndexedMesh m;
  m.points = hex.points;
  // Kuhn: the six monotone paths 0 -> 6 through the cube; each (0, a, b, 6) is positive for
  // the orders below (VTK hex numbering).
  static constexpr std::uint32_t kuhn[6][4] = {{0, 1, 2, 6}, {0, 2, 3, 6}, {0, 3, 7, 6},
                                               {0, 7, 4, 6}, {0, 4, 5, 6}, {0, 5, 1, 6}};
  // Five tets: four corners and a central one, for the two parities of a cell.
  static constexpr std::uint32_t five_even[5][4] = {{0, 1, 3, 4}, {1, 2, 3, 6}, {1, 4, 5, 6}, {3, 6, 7, 4},
                                                    {1, 3, 4, 6}};
  static constexpr std::uint32_t five_odd[5][4] = {{1, 2, 0, 5}, {2, 3, 0, 7}, {2, 5, 6, 7}, {0, 7, 4, 5},
                                                   {0, 2, 7, 5}};
  std::uint32_t c = 0;
  for (std::uint32_t k = 0; k < nz; ++k)
    for (std::uint32_t j = 0; j < ny; ++j)
      for (std::uint32_t i = 0; i < nx; ++i, ++c) {
        const auto h = hex.cell(c);
        auto emit = [&](const std::uint32_t (&t)[4]) {
          std::array<std::uint32_t, 4> v{h[t[0]], h[t[1]], h[t[2]], h[t[3]]};
          const auto& p0 = m.points[v[0]];
          const auto& p1 = m.points[v[1]];
          const auto& p2 = m.points[v[2]];
          const auto& p3 = m.points[v[3]];
          const double ax = p1[0] - p0[0], ay = p1[1] - p0[1], az = p1[2] - p0[2];
          const double bx = p2[0] - p0[0], by = p2[1] - p0[1], bz = p2[2] - p0[2];
          const double cx = p3[0] - p0[0], cy = p3[1] - p0[1], cz = p3[2] - p0[2];
          const double vol = ax * (by * cz - bz * cy) - ay * (bx * cz - bz * cx) + az * (bx * cy - by * cx);
          if (vol < 0) std::swap(v[1], v[2]);  // keep every tetrahedron positively oriented
          m.add_cell(CellType::tetrahedron, v);
        };
        if (split == TetSplit::kuhn6) {
          for (const auto& t : kuhn) emit(t);
        } else if ((i + j + k) % 2 == 0) {
          for (const auto& t : five_even) emit(t);
        } else {
          for (const auto& t : five_odd) emit(t);
        }
      }
  return m;
}

IndexedMesh quad_grid(std::uint32_t nx, std::uint32_t ny, const GridSpec& g) {
  check_grid(nx, ny, 1, g, "quad_grid");
  IndexedMesh m;
  for (std::uint32_t j = 0; j <= ny; ++j)
    for (std::uint32_t i = 0; i <= nx; ++i) m.points.push_back(grid_point(g, i, j, 0));
  auto id = [&](std::uint32_t i, std::uint32_t j) { return i + (nx + 1) * j; };
  for (std::uint32_t j = 0; j < ny; ++j)
    for (std::uint32_t i = 0; i < nx; ++i)
      m.add_cell(CellType::quad, {id(i, j), id(i + 1, j), id(i + 1, j + 1), id(i, j + 1)});
  return m;
}

IndexedMesh tri_grid(std::uint32_t nx, std::uint32_t ny, const GridSpec& g) {
  IndexedMesh q = quad_grid(nx, ny, g);
  IndexedMesh m;
  m.points = q.points;
  for (std::uint32_t c = 0; c < q.num_cells(); ++c) {
    const auto v = q.cell(c);
    m.add_cell(CellType::triangle, {v[0], v[1], v[2]});
    m.add_cell(CellType::triangle, {v[0], v[2], v[3]});
  }
  return m;
}

IndexedMesh polyline_x(std::uint32_t n, double spacing) {
  if (n == 0 || !(spacing > 0)) throw MeshError("polyline_x: needs n >= 1 segments and a positive spacing");
  IndexedMesh m;
  for (std::uint32_t i = 0; i <= n; ++i) m.points.push_back({i * spacing, 0.0, 0.0});
  for (std::uint32_t i = 0; i < n; ++i) m.add_cell(CellType::segment, {i, i + 1});
  return m;
}

IndexedMesh box_union(std::span<const LatticeBox> boxes, const GridSpec& g) {
  check_grid(1, 1, 1, g, "box_union");
  if (boxes.empty()) throw MeshError("box_union: no box");
  // 64-bit bounds: hi - lo of two ints may not fit in an int
  std::array<std::int64_t, 3> lo{}, hi{};
  for (std::size_t b = 0; b < boxes.size(); ++b)
    for (std::size_t a = 0; a < 3; ++a) {
      if (boxes[b].hi[a] <= boxes[b].lo[a])
        throw MeshError("box_union: box " + std::to_string(b) + " is empty or inverted along axis " + std::to_string(a));
      lo[a] = b ? std::min<std::int64_t>(lo[a], boxes[b].lo[a]) : boxes[b].lo[a];
      hi[a] = b ? std::max<std::int64_t>(hi[a], boxes[b].hi[a]) : boxes[b].hi[a];
    }
  constexpr std::int64_t max_cells = std::int64_t{1} << 28;
  if (hi[0] - lo[0] > max_cells || hi[1] - lo[1] > max_cells || hi[2] - lo[2] > max_cells ||
      (hi[0] - lo[0]) * (hi[1] - lo[1]) > max_cells || (hi[0] - lo[0]) * (hi[1] - lo[1]) * (hi[2] - lo[2]) > max_cells)
    throw MeshError("box_union: the boxes' bounding box spans more than 2^28 cells");
  // dense flags over the bounding box of the union: which cells are covered, which points used
  const std::array<std::size_t, 3> n{static_cast<std::size_t>(hi[0] - lo[0]), static_cast<std::size_t>(hi[1] - lo[1]),
                                     static_cast<std::size_t>(hi[2] - lo[2])};
  std::vector<char> covered(n[0] * n[1] * n[2], 0);
  auto cell = [&](std::size_t i, std::size_t j, std::size_t k) { return i + n[0] * (j + n[1] * k); };
  for (const LatticeBox& b : boxes)
    for (int k = b.lo[2]; k < b.hi[2]; ++k)
      for (int j = b.lo[1]; j < b.hi[1]; ++j)
        for (int i = b.lo[0]; i < b.hi[0]; ++i)
          covered[cell(static_cast<std::size_t>(i - lo[0]), static_cast<std::size_t>(j - lo[1]), static_cast<std::size_t>(k - lo[2]))] = 1;
  const std::array<std::size_t, 3> p{n[0] + 1, n[1] + 1, n[2] + 1};
  std::vector<std::uint32_t> point_of(p[0] * p[1] * p[2], std::numeric_limits<std::uint32_t>::max());
  IndexedMesh m;
  auto point = [&](std::size_t i, std::size_t j, std::size_t k) {
    std::uint32_t& q = point_of[i + p[0] * (j + p[1] * k)];
    if (q == std::numeric_limits<std::uint32_t>::max()) {
      q = static_cast<std::uint32_t>(m.points.size());
      const std::array<std::size_t, 3> at{i, j, k};
      Point3 x;
      for (std::size_t a = 0; a < 3; ++a) x[a] = g.origin[a] + (static_cast<double>(at[a]) + static_cast<double>(lo[a])) * g.spacing[a];
      m.points.push_back(x);
    }
    return q;
  };
  for (std::size_t k = 0; k < n[2]; ++k)
    for (std::size_t j = 0; j < n[1]; ++j)
      for (std::size_t i = 0; i < n[0]; ++i)
        if (covered[cell(i, j, k)])
          m.add_cell(CellType::hexahedron, {point(i, j, k), point(i + 1, j, k), point(i + 1, j + 1, k), point(i, j + 1, k),
                                            point(i, j, k + 1), point(i + 1, j, k + 1), point(i + 1, j + 1, k + 1),
                                            point(i, j + 1, k + 1)});
  return m;
}

IndexedMesh polyline(std::span<const Point3> points) {
  if (points.size() < 2) throw MeshError("polyline: needs at least 2 points");
  IndexedMesh m;
  m.points.assign(points.begin(), points.end());
  for (std::uint32_t i = 0; i + 1 < points.size(); ++i) {
    if (points[i] == points[i + 1]) throw MeshError("polyline: points " + std::to_string(i) + " and " + std::to_string(i + 1) + " coincide");
    m.add_cell(CellType::segment, {i, i + 1});
  }
  return m;
}

IndexedMesh disc(double radius, std::uint32_t rings, std::uint32_t sectors) {
  if (!(radius > 0) || rings == 0 || sectors < 3) throw MeshError("disc: needs radius > 0, rings >= 1 and sectors >= 3");
  IndexedMesh m;
  m.points.push_back({0, 0, 0});
  std::vector<std::uint32_t> ring_start{0, 1};  // ring k starts at ring_start[k]
  for (std::uint32_t k = 1; k <= rings; ++k) {
    const std::uint32_t n = sectors * k;
    for (std::uint32_t i = 0; i < n; ++i) {
      const double a = 2 * std::numbers::pi * i / n, r = radius * k / rings;
      m.points.push_back({r * std::cos(a), r * std::sin(a), 0});
    }
    ring_start.push_back(ring_start.back() + n);
  }
  // Between ring k-1 (sectors·(k-1) points) and ring k (sectors·k): in each sector, walk both
  // rings by angle, always advancing the one whose next point comes first (ties: outer ring).
  for (std::uint32_t k = 1; k <= rings; ++k) {
    const std::uint32_t inner_n = std::max<std::uint32_t>(sectors * (k - 1), 1), outer_n = sectors * k;
    auto inner = [&](std::uint32_t i) { return k == 1 ? 0u : ring_start[k - 1] + i % inner_n; };
    auto outer = [&](std::uint32_t i) { return ring_start[k] + i % outer_n; };
    std::uint32_t i = 0, o = 0;
    while (i < (k == 1 ? 0u : inner_n) || o < outer_n) {
      // angles of the next candidate points, as fractions of a turn
      const double next_inner = k == 1 ? 2.0 : double(i + 1) / inner_n;
      const double next_outer = double(o + 1) / outer_n;
      if (next_outer <= next_inner + 1e-12) {
        m.add_cell(CellType::triangle, {inner(i), outer(o), outer(o + 1)});
        ++o;
      } else {
        m.add_cell(CellType::triangle, {inner(i), outer(o), inner(i + 1)});
        ++i;
      }
    }
  }
  return m;
}

IndexedMesh cylinder(double radius, double height, std::uint32_t rings, std::uint32_t sectors, std::uint32_t layers) {
  if (!(height > 0) || layers == 0) throw MeshError("cylinder: needs height > 0 and layers >= 1");
  const IndexedMesh base = disc(radius, rings, sectors);
  const std::uint32_t np = base.num_points();
  IndexedMesh m;
  for (std::uint32_t l = 0; l <= layers; ++l)
    for (const auto& p : base.points) m.points.push_back({p[0], p[1], height * l / layers});
  for (std::uint32_t l = 0; l < layers; ++l)
    for (std::uint32_t c = 0; c < base.num_cells(); ++c) {
      const auto t = base.cell(c);
      std::array<std::uint32_t, 6> v{t[0] + l * np, t[1] + l * np, t[2] + l * np,
                                     t[0] + (l + 1) * np, t[1] + (l + 1) * np, t[2] + (l + 1) * np};
      // Put the smallest point index first by a rotation of the triangles and/or swapping the
      // two layers; then every quad face is cut along the diagonal from its smallest index, which
      // neighbouring prisms see the same way, so the tetrahedra conform (Dompierre et al. 1999).
      const auto min_at = static_cast<std::size_t>(std::min_element(v.begin(), v.end()) - v.begin());
      if (min_at >= 3) std::swap_ranges(v.begin(), v.begin() + 3, v.begin() + 3);
      std::rotate(v.begin(), v.begin() + static_cast<long>(min_at % 3), v.begin() + 3);
      std::rotate(v.begin() + 3, v.begin() + 3 + static_cast<long>(min_at % 3), v.end());
      const auto [a, b, c2, d, e, f] = v;  // a-b-c2 one triangle, d-e-f the other (d over a)
      std::array<std::array<std::uint32_t, 4>, 3> tets;
      if (std::min(b, f) < std::min(c2, e))
        tets = {{{a, b, c2, f}, {a, b, f, e}, {a, e, f, d}}};
      else
        tets = {{{a, b, c2, e}, {a, c2, f, e}, {a, e, f, d}}};
      for (auto tv : tets) {
        const auto& p0 = m.points[tv[0]];
        auto sub = [&](std::uint32_t q) {
          const auto& p = m.points[q];
          return std::array<double, 3>{p[0] - p0[0], p[1] - p0[1], p[2] - p0[2]};
        };
        const auto x = sub(tv[1]), y = sub(tv[2]), z = sub(tv[3]);
        const double vol = x[0] * (y[1] * z[2] - y[2] * z[1]) - x[1] * (y[0] * z[2] - y[2] * z[0]) + x[2] * (y[0] * z[1] - y[1] * z[0]);
        if (vol < 0) std::swap(tv[1], tv[2]);
        m.add_cell(CellType::tetrahedron, tv);
      }
    }
  return m;
}

void place_in_plane(IndexedMesh& mesh, const std::string& plane) {
  if (plane == "xy") return;
  if (plane != "xz" && plane != "yz") throw MeshError("place_in_plane: unknown plane \"" + plane + "\" (xy, xz or yz)");
  for (auto& p : mesh.points) p = plane == "xz" ? Point3{p[0], 0.0, p[1]} : Point3{0.0, p[0], p[1]};
}

void transform(IndexedMesh& mesh, double scale, const Point3& offset) {
  for (auto& p : mesh.points)
    for (int k = 0; k < 3; ++k) p[static_cast<std::size_t>(k)] = scale * p[static_cast<std::size_t>(k)] + offset[static_cast<std::size_t>(k)];
}

std::uint32_t append(IndexedMesh& mesh, const IndexedMesh& other) {
  const std::uint32_t base = mesh.num_points();
  mesh.points.insert(mesh.points.end(), other.points.begin(), other.points.end());
  for (std::uint32_t c = 0; c < other.num_cells(); ++c) {
    std::array<std::uint32_t, 8> v{};
    const auto cv = other.cell(c);
    for (std::size_t k = 0; k < cv.size(); ++k) v[k] = cv[k] + base;
    mesh.add_cell(other.types[c], std::span<const std::uint32_t>(v.data(), cv.size()), other.tags[c]);
  }
  return base;
}

}  // namespace sewn
