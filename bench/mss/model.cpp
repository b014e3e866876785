#include "model.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <random>
#include <stdexcept>

#include <Eigen/Core>

#include "sewn/physics/springs.hpp"
#include "sewn/physics/stiffness.hpp"

namespace sewn::bench::mss {

namespace {

Eigen::Vector3d point(const IndexedMesh& m, std::uint32_t p) { return {m.points[p][0], m.points[p][1], m.points[p][2]}; }

// Local edges of a VTK hexahedron by axis (x, y, z for an axis-aligned box), and its body diagonals.
constexpr std::uint32_t hex_edges[3][4][2] = {{{0, 1}, {3, 2}, {4, 5}, {7, 6}},
                                              {{0, 3}, {1, 2}, {4, 7}, {5, 6}},
                                              {{0, 4}, {1, 5}, {2, 6}, {3, 7}}};
constexpr std::uint32_t hex_diagonals[4][2] = {{0, 6}, {1, 7}, {2, 4}, {3, 5}};
// The order of physics::van_gelder_tet's contributions.
constexpr std::uint32_t tet_edges[6][2] = {{0, 1}, {0, 2}, {0, 3}, {1, 2}, {1, 3}, {2, 3}};

double mesh_extent(const IndexedMesh& m) {
  double lo = std::numeric_limits<double>::infinity(), hi = -lo;
  for (const Point3& p : m.points)
    for (double c : p) {
      lo = std::min(lo, c);
      hi = std::max(hi, c);
    }
  return hi - lo;
}

}  // namespace

void clamp_plane(ModelSpec& spec, int axis, double value) {
  const double tol = 1e-9 * mesh_extent(spec.mesh);
  spec.fixed.resize(spec.mesh.num_points(), 0);
  for (std::uint32_t p = 0; p < spec.mesh.num_points(); ++p)
    if (std::abs(spec.mesh.points[p][static_cast<std::size_t>(axis)] - value) <= tol) spec.fixed[p] = 1;
}

MassSpring mass_spring(const ModelSpec& spec) {
  const IndexedMesh& m = spec.mesh;
  const Material& mat = spec.material;
  MassSpring out;
  out.mass.assign(m.num_points(), 0.0);
  struct Edge {
    std::uint32_t a, b;
    double k, l;
  };
  std::vector<Edge> edges;  // one entry per (cell, edge); merged below
  std::vector<Edge> diagonals;
  for (std::uint32_t c = 0; c < m.num_cells(); ++c) {
    const auto v = m.cell(c);
    if (m.types[c] == CellType::hexahedron) {
      // Box sizes: the mean length of the 4 parallel edges (exact for the boxes used here).
      double len[3] = {0, 0, 0};
      for (int a = 0; a < 3; ++a)
        for (const auto& e : hex_edges[a]) {
          const Eigen::Vector3d d = point(m, v[e[1]]) - point(m, v[e[0]]);
          // the Baudet formula is defined for boxes only: refuse anything else
          if (std::abs(std::abs(d[a]) - d.norm()) > 1e-9 * d.norm())
            throw std::runtime_error(spec.name + ": hexahedron " + std::to_string(c) + " is not an axis-aligned box");
          len[a] += d.norm() / 4;
        }
      const physics::BoxStiffness ks = physics::baudet_box(mat.young, mat.poisson, len[0], len[1], len[2]);
      if (!ks.valid()) throw std::runtime_error(spec.name + ": " + physics::describe(ks));
      const double corner = physics::lumped_corner_mass(mat.density, len[0] * len[1] * len[2], 8);
      for (std::uint32_t q = 0; q < 8; ++q) out.mass[v[q]] += corner;
      for (int a = 0; a < 3; ++a)
        for (const auto& e : hex_edges[a]) edges.push_back({v[e[0]], v[e[1]], ks.edge[static_cast<std::size_t>(a)], len[a]});
      for (const auto& e : hex_diagonals)
        diagonals.push_back({v[e[0]], v[e[1]], ks.diagonal, (point(m, v[e[1]]) - point(m, v[e[0]])).norm()});
    } else if (m.types[c] == CellType::tetrahedron) {
      const Eigen::Vector3d p0 = point(m, v[0]), p1 = point(m, v[1]), p2 = point(m, v[2]), p3 = point(m, v[3]);
      const std::array<double, 6> k = physics::van_gelder_tet(mat.young, p0, p1, p2, p3);
      const double corner = physics::lumped_corner_mass(mat.density, physics::tet_volume(p0, p1, p2, p3), 4);
      for (std::uint32_t q = 0; q < 4; ++q) out.mass[v[q]] += corner;
      for (std::size_t e = 0; e < 6; ++e) {
        const std::uint32_t a = v[tet_edges[e][0]], b = v[tet_edges[e][1]];
        edges.push_back({a, b, k[e], (point(m, b) - point(m, a)).norm()});
      }
    } else {
      throw std::runtime_error(spec.name + ": cell " + std::to_string(c) + " is a " + to_string(m.types[c]) +
                               "; the mss suite builds hexahedra and tetrahedra only");
    }
  }
  // Merge the copies of each edge: its stiffness is the sum over its incident elements.
  for (Edge& e : edges)
    if (e.a > e.b) std::swap(e.a, e.b);
  std::sort(edges.begin(), edges.end(), [](const Edge& x, const Edge& y) { return x.a != y.a ? x.a < y.a : x.b < y.b; });
  auto push = [&](const Edge& e) {
    out.i.push_back(e.a);
    out.j.push_back(e.b);
    out.k.push_back(e.k);
    out.l.push_back(e.l);
  };
  for (std::size_t s = 0; s < edges.size();) {
    Edge e = edges[s++];
    for (; s < edges.size() && edges[s].a == e.a && edges[s].b == e.b; ++s) e.k += edges[s].k;
    push(e);
  }
  out.edges = out.k.size();
  for (const Edge& e : diagonals) push(e);
  out.diagonals = diagonals.size();
  for (std::size_t s = 0; s < out.k.size(); ++s)
    out.gamma.push_back(physics::paper_viscosity(out.k[s], out.mass[out.i[s]], out.mass[out.j[s]]));
  return out;
}

std::string to_string(const Counts& c) {
  return std::to_string(c.particles) + " particles, " + std::to_string(c.springs) + " springs";
}

State rest_state(const ModelSpec& spec) {
  State s;
  for (const Point3& p : spec.mesh.points) s.x.insert(s.x.end(), p.begin(), p.end());
  s.v.assign(s.x.size(), 0.0);
  return s;
}

State perturbed_state(const ModelSpec& spec, double amplitude, double speed, unsigned seed) {
  State s = rest_state(spec);
  double shortest = std::numeric_limits<double>::infinity();
  const MassSpring ms = mass_spring(spec);
  for (double l : ms.l) shortest = std::min(shortest, l);
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  for (std::size_t p = 0; p < spec.mesh.num_points(); ++p) {
    if (!spec.fixed.empty() && spec.fixed[p] != 0) continue;
    for (std::size_t a = 0; a < 3; ++a) {
      s.x[3 * p + a] += amplitude * shortest * u(rng);
      s.v[3 * p + a] = speed * u(rng);
    }
  }
  return s;
}

double relative_difference(std::span<const double> a, std::span<const double> b) {
  if (a.size() != b.size()) return std::numeric_limits<double>::infinity();
  double diff = 0, scale = 0;
  for (std::size_t k = 0; k < a.size(); ++k) {
    diff = std::max(diff, std::abs(a[k] - b[k]));
    scale = std::max(scale, std::abs(a[k]));
  }
  if (!(std::isfinite(diff) && std::isfinite(scale))) return std::numeric_limits<double>::infinity();
  return scale > 0 ? diff / scale : diff;
}

#ifndef SEWN_HAVE_CGAL
bool have_cgal_peer() { return false; }
std::string cgal_peer_name() { return "CGAL (not built)"; }
std::unique_ptr<PeerModel> make_cgal_peer(const ModelSpec&) {
  throw std::runtime_error("bench_mss was built without CGAL: no LCC+MSS peer");
}
#endif

}  // namespace sewn::bench::mss
