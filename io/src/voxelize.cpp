#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <string>
#include <utility>
#include <vector>

#include "sewn/io/surface.hpp"

namespace sewn::io {

namespace {

// 2^22 grid cells (a cube at 161 cells a side): the mesh of a full grid takes about 70 bytes a
// hexahedron (a point, 8 corners, type, tag), 300 MB here, and a simulation about 4 kB more
// each. A flat surface's rows or a cube's cells past this ran into gigabytes, not into an error.
constexpr double max_grid_cells = 4194304.0;

std::string number(double x) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.6g", x);
  return buf;
}

// Every edge must be shared by exactly two triangles, or the parity of crossings means nothing.
void require_closed(const Surface& s, const std::string& source) {
  std::map<std::pair<std::uint32_t, std::uint32_t>, int> uses;
  for (const auto& t : s.triangles)
    for (int e = 0; e < 3; ++e) {
      const std::uint32_t a = t[static_cast<std::size_t>(e)], b = t[static_cast<std::size_t>((e + 1) % 3)];
      ++uses[{std::min(a, b), std::max(a, b)}];
    }
  for (const auto& [edge, n] : uses)
    if (n != 2)
      throw SemanticError(source, 0, "the surface is not closed: the edge between vertices " + std::to_string(edge.first) + " and " +
                                         std::to_string(edge.second) + " belongs to " + std::to_string(n) +
                                         " triangles (2 needed to voxelize)");
}

// Exact arithmetic on doubles (Shewchuk 1997, "Adaptive precision floating-point arithmetic"):
// a + b and a * b as an unevaluated sum hi + lo of two doubles, with no rounding error.
// std::fma is exact on every platform, so the product's tail does not depend on whether the
// compiler contracts a * b - c * d (it does with -march=native, differently at each inlined
// call: the edge signs of two triangles sharing an edge then disagree and a closed surface
// is crossed an odd number of times, as CGAL's mpi.off was at every resolution).
struct Two {
  double hi, lo;
};
Two two_sum(double a, double b) {
  const double x = a + b, bv = x - a, av = x - bv;
  return {x, (a - av) + (b - bv)};
}
Two two_product(double a, double b) {
  const double x = a * b;
  return {x, std::fma(a, b, -x)};
}

// Sign of the sum of the terms, exactly: they are added into a non-overlapping expansion
// (Grow-Expansion), whose largest non-zero component has the sign of the sum.
template <std::size_t N>
int exact_sign(const std::array<double, N>& terms) {
  std::array<double, N> e{};
  std::size_t n = 0;
  for (double q : terms) {
    for (std::size_t i = 0; i < n; ++i) {
      const Two s = two_sum(q, e[i]);
      e[i] = s.lo;
      q = s.hi;
    }
    e[n++] = q;
  }
  for (std::size_t i = n; i-- > 0;)
    if (e[i] != 0) return e[i] > 0 ? 1 : -1;
  return 0;
}

// Sign of the orientation (b - a) x (q - a) of three points of the y-z plane, exact: the
// rounded value when it is far from 0, else its 16 exact product terms summed exactly.
int orientation(const Point3& a, const Point3& b, double qy, double qz) {
  const double ey = b[1] - a[1], ez = b[2] - a[2], dy = qy - a[1], dz = qz - a[2];
  const double left = ey * dz, right = ez * dy, det = left - right;
  const double bound = 4 * std::numeric_limits<double>::epsilon() * (std::abs(left) + std::abs(right));
  if (det > bound) return 1;
  if (det < -bound) return -1;
  // each difference exactly as hi + lo, each product of two such as 4 exact products
  const Two y = two_sum(b[1], -a[1]), z = two_sum(b[2], -a[2]), qy2 = two_sum(qy, -a[1]), qz2 = two_sum(qz, -a[2]);
  std::array<double, 16> t{};
  std::size_t n = 0;
  auto add = [&](double u, double v, double sign) {
    const Two p = two_product(u, v);
    t[n++] = sign * p.hi;
    t[n++] = sign * p.lo;
  };
  for (double u : {y.hi, y.lo})
    for (double v : {qz2.hi, qz2.lo}) add(u, v, 1);
  for (double u : {z.hi, z.lo})
    for (double v : {qy2.hi, qy2.lo}) add(u, v, -1);
  return exact_sign(t);
}

// Sign of the edge function of edge a -> b (points in the y-z plane) at q, q perturbed by
// (eps, eps^2): +1 or -1, never 0 for a non-degenerate edge. Exact, so two triangles sharing
// an edge see opposite signs and a point on it falls in exactly one of them.
int edge_sign(const std::vector<Point3>& points, std::uint32_t ia, std::uint32_t ib, double qy, double qz) {
  const Point3& a = points[ia];
  const Point3& b = points[ib];
  if (const int o = orientation(a, b, qy, qz); o != 0) return o;
  // on the edge's line: the perturbation decides, w(q + (eps, eps^2)) = ey eps^2 - ez eps
  const double ey = b[1] - a[1], ez = b[2] - a[2];
  return ez != 0 ? (ez > 0 ? -1 : 1) : (ey > 0 ? 1 : -1);
}

// The surface's points in grid units: the grid's corner at the origin, cells of side 1, cell
// centres at i + 1/2. The exact signs never overflow or underflow there (at 1e200 their products
// were inf and the crossings NaN), and each vertex maps to one point, so shared edges stay shared.
std::vector<Point3> in_grid_units(const Surface& s, const Point3& lo, double a) {
  std::vector<Point3> g(s.points.size());
  for (std::size_t v = 0; v < g.size(); ++v)
    for (std::size_t k = 0; k < 3; ++k) g[v][k] = (s.points[v][k] - lo[k]) / a;
  return g;
}

// First and last row (or column) of centres i + 1/2 in [lo, hi], in grid units, clamped to the grid.
int first_row(double lo) { return std::max(0, static_cast<int>(std::ceil(lo - 0.5))); }
int last_row(double hi, int n) { return std::min(n - 1, static_cast<int>(std::floor(hi - 0.5))); }

// The x of every crossing of the ray through each row's cell centres (row j + n[1] k), in grid units.
std::vector<std::vector<double>> crossings(const std::vector<Point3>& g, const Surface& s, const std::array<int, 3>& n) {
  std::vector<std::vector<double>> hits(static_cast<std::size_t>(n[1]) * static_cast<std::size_t>(n[2]));
  for (const auto& t : s.triangles) {
    const Point3 &p0 = g[t[0]], &p1 = g[t[1]], &p2 = g[t[2]];
    // A triangle parallel to the rays (zero area seen along x) needs no test: its three
    // exact perturbed edge signs never agree, so the rays never cross it.
    const double ylo = std::min({p0[1], p1[1], p2[1]}), yhi = std::max({p0[1], p1[1], p2[1]});
    const double zlo = std::min({p0[2], p1[2], p2[2]}), zhi = std::max({p0[2], p1[2], p2[2]});
    const double xlo = std::min({p0[0], p1[0], p2[0]}), xhi = std::max({p0[0], p1[0], p2[0]});
    for (int k = first_row(zlo); k <= last_row(zhi, n[2]); ++k)
      for (int j = first_row(ylo); j <= last_row(yhi, n[1]); ++j) {
        const double qy = j + 0.5, qz = k + 0.5;
        const int s0 = edge_sign(g, t[1], t[2], qy, qz), s1 = edge_sign(g, t[2], t[0], qy, qz), s2 = edge_sign(g, t[0], t[1], qy, qz);
        if (s0 != s1 || s1 != s2) continue;
        // barycentric weights from the unperturbed edge functions (the crossing's x)
        auto w = [&](const Point3& u, const Point3& v) { return (v[1] - u[1]) * (qz - u[2]) - (v[2] - u[2]) * (qy - u[1]); };
        const double w0 = w(p1, p2), w1 = w(p2, p0), w2 = w(p0, p1), sum = w0 + w1 + w2;
        // a sliver seen edge-on (rounded weights summing to 0): its vertices' mean x; rounded
        // weights of mixed signs over a tiny sum land anywhere: the crossing is on the triangle
        const double x = sum != 0 ? (w0 * p0[0] + w1 * p1[0] + w2 * p2[0]) / sum : (p0[0] + p1[0] + p2[0]) / 3;
        hits[static_cast<std::size_t>(j) + static_cast<std::size_t>(n[1]) * static_cast<std::size_t>(k)].push_back(std::clamp(x, xlo, xhi));
      }
  }
  return hits;
}

// The grid: its corner, its cells' side, how many along each axis. Refuses (naming the source)
// any grid the voxelizer cannot make exactly or within its memory bound.
struct Grid {
  Point3 lo;
  double a;
  std::array<int, 3> n;
};

Grid grid_for(const Surface& s, std::uint32_t cells, const std::string& source) {
  Point3 lo{INFINITY, INFINITY, INFINITY}, hi{-INFINITY, -INFINITY, -INFINITY};
  for (const Point3& p : s.points)
    for (std::size_t k = 0; k < 3; ++k) lo[k] = std::min(lo[k], p[k]), hi[k] = std::max(hi[k], p[k]);
  const double longest = std::max({hi[0] - lo[0], hi[1] - lo[1], hi[2] - lo[2]});
  if (!(longest > 0)) throw SemanticError(source, 0, "the surface has no extent to voxelize");
  // coordinates from -1e308 to 1e308 overflow the extent; a few subnormal ones make a cube of side 0
  if (!std::isfinite(longest) || !(longest / cells > 0))
    throw SemanticError(source, 0, "the surface's extent, " + number(longest) + ", cannot be cut into " + std::to_string(cells) + " cells");
  const double a = longest / cells;
  // Corners lo + i a round together when a is near the rounding unit of the coordinates (a
  // surface 1e-5 across at 1e10 from the origin gave hexahedra of zero volume, silently).
  const double far = std::max({std::abs(lo[0]), std::abs(lo[1]), std::abs(lo[2]), std::abs(hi[0]), std::abs(hi[1]), std::abs(hi[2])});
  if (a < 1e-9 * far)
    throw SemanticError(source, 0, "cells of side " + number(a) + " are too small for a surface " + number(far) +
                                       " from the origin (their corners would round together): use fewer cells or move the surface");
  // counted in double first: cells near 2^32 overflow an int
  std::array<double, 3> along{};
  for (std::size_t k = 0; k < 3; ++k) along[k] = std::max(1.0, std::ceil((hi[k] - lo[k]) / a));
  const double total = along[0] * along[1] * along[2];
  if (total > max_grid_cells)
    throw SemanticError(source, 0, "voxelizing at " + std::to_string(cells) + " cells makes a grid of " + number(total) +
                                       " cells, more than the 2^22 the voxelizer makes (about 300 MB of mesh)");
  return {lo, a, {static_cast<int>(along[0]), static_cast<int>(along[1]), static_cast<int>(along[2])}};
}

}  // namespace

IndexedMesh voxelize(const Surface& s, std::uint32_t cells, const std::string& source) {
  if (cells < 1) throw SemanticError(source, 0, "voxelize: at least 1 cell along the longest side is needed");
  require_closed(s, source);
  const auto [lo, a, n] = grid_for(s, cells, source);
  std::vector<std::vector<double>> hits = crossings(in_grid_units(s, lo, a), s, n);
  std::vector<LatticeBox> boxes;
  for (int k = 0; k < n[2]; ++k)
    for (int j = 0; j < n[1]; ++j) {
      auto& h = hits[static_cast<std::size_t>(j) + static_cast<std::size_t>(n[1]) * static_cast<std::size_t>(k)];
      if (h.size() % 2 != 0)
        throw SemanticError(source, 0, "the ray along x at y = " + number(lo[1] + (j + 0.5) * a) + ", z = " + number(lo[2] + (k + 0.5) * a) +
                                           " crosses the surface " + std::to_string(h.size()) +
                                           " times, an odd number: the surface does not enclose a volume");
      std::sort(h.begin(), h.end());
      for (std::size_t p = 0; p < h.size(); p += 2) {
        // cells whose centre x lies in [h[p], h[p+1])
        const int i0 = first_row(h[p]), i1 = std::min(n[0] - 1, static_cast<int>(std::ceil(h[p + 1] - 0.5)) - 1);
        if (i1 >= i0) boxes.push_back({{i0, j, k}, {i1 + 1, j + 1, k + 1}});
      }
    }
  if (boxes.empty())
    throw SemanticError(source, 0, "no cell centre lies inside the surface at " + std::to_string(cells) + " cells along its longest side: use more");
  return box_union(boxes, GridSpec{{a, a, a}, lo});
}

}  // namespace sewn::io
