// The 2019 paper's scene meshes from their published counts (paper_shapes.hpp, PHYSICS_NOTES §5).
// Every builder places its parts so that they share nodes where the paper's parts are joined:
// a rod on a shell's edges or at one of its points, a rod ending at a solid's point, shells on
// tetrahedron faces.
#include "sewn/apps/paper_shapes.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <functional>
#include <numbers>
#include <numeric>
#include <optional>
#include <set>
#include <stdexcept>

namespace sewn::app {

namespace {

constexpr double pi = std::numbers::pi;

enum Dim { rod = 1, shell = 2, solid = 3 };

std::uint32_t add_point(IndexedMesh& m, const Point3& p) {
  m.points.push_back(p);
  return m.num_points() - 1;
}

// Triangles between two closed rings of points (CCW about +z seen from above, `inner` inside
// `outer`, both starting at angle 0 and evenly spaced): walk both by angle, advancing the ring
// whose next point comes first; a + b triangles (b when `inner` is one centre point).
void zip_rings(IndexedMesh& m, const std::vector<std::uint32_t>& inner, const std::vector<std::uint32_t>& outer,
               std::int32_t tag) {
  const auto a = inner.size(), b = outer.size();
  const bool centre = a == 1;
  std::size_t i = 0, o = 0;
  while ((!centre && i < a) || o < b) {
    const double next_inner = centre ? 2.0 : double(i + 1) / double(a);
    const double next_outer = double(o + 1) / double(b);
    if (next_outer <= next_inner + 1e-12) {
      m.add_cell(CellType::triangle, {inner[i % a], outer[o % b], outer[(o + 1) % b]}, tag);
      ++o;
    } else {
      m.add_cell(CellType::triangle, {inner[i % a], outer[o % b], inner[(i + 1) % a]}, tag);
      ++i;
    }
  }
}

// A disc in the z = 0 plane: a centre and closed rings of the given sizes at parameters
// ρ = k / rings, angle 2πj / n_k, placed at place(ρ, angle). Returns each ring's points.
std::vector<std::vector<std::uint32_t>> ring_disc(IndexedMesh& m, const std::vector<std::uint32_t>& counts,
                                                  const std::function<Point3(double, double)>& place, std::int32_t tag) {
  std::vector<std::vector<std::uint32_t>> rings{{add_point(m, place(0.0, 0.0))}};
  for (std::size_t k = 0; k < counts.size(); ++k) {
    std::vector<std::uint32_t> ring;
    const double rho = double(k + 1) / double(counts.size());
    for (std::uint32_t j = 0; j < counts[k]; ++j) ring.push_back(add_point(m, place(rho, 2 * pi * j / counts[k])));
    zip_rings(m, rings.back(), ring, tag);
    rings.push_back(std::move(ring));
  }
  return rings;
}

// Segments along a chain of points.
void add_chain(IndexedMesh& m, const std::vector<std::uint32_t>& chain, std::int32_t tag) {
  for (std::size_t i = 0; i + 1 < chain.size(); ++i) m.add_cell(CellType::segment, {chain[i], chain[i + 1]}, tag);
}

// A rod of `edges` segments from point `from` along curve(s), s in (0, 1]; `to` (if given) is
// the last point instead of curve(1).
void add_rod(IndexedMesh& m, std::uint32_t from, std::uint32_t edges, const std::function<Point3(double)>& curve,
             std::int32_t tag, std::optional<std::uint32_t> to = std::nullopt) {
  std::vector<std::uint32_t> chain{from};
  for (std::uint32_t i = 1; i <= edges; ++i)
    chain.push_back(i == edges && to ? *to : add_point(m, curve(double(i) / edges)));
  add_chain(m, chain, tag);
}

// A closed band of rings × around points, point (j, i) at place(j, i), joined ring to ring by
// quads split along their diagonal (j, i)–(j + 1, i + 1). Returns point (j, i)'s index (i taken
// modulo around).
std::function<std::uint32_t(std::uint32_t, std::uint32_t)> split_quad_band(
    IndexedMesh& m, std::uint32_t rings, std::uint32_t around, const std::function<Point3(std::uint32_t, std::uint32_t)>& place,
    std::int32_t tag) {
  const std::uint32_t first = m.num_points();
  auto v = [=](std::uint32_t j, std::uint32_t i) { return first + j * around + i % around; };
  for (std::uint32_t j = 0; j < rings; ++j)
    for (std::uint32_t i = 0; i < around; ++i) m.points.push_back(place(j, i));
  for (std::uint32_t j = 0; j + 1 < rings; ++j)
    for (std::uint32_t i = 0; i < around; ++i) {
      m.add_cell(CellType::triangle, {v(j, i), v(j + 1, i), v(j + 1, i + 1)}, tag);
      m.add_cell(CellType::triangle, {v(j, i), v(j + 1, i + 1), v(j, i + 1)}, tag);
    }
  return v;
}

double signed_volume(const IndexedMesh& m, const std::array<std::uint32_t, 4>& t) {
  const auto& p0 = m.points[t[0]];
  auto d = [&](int k) {
    const auto& p = m.points[t[static_cast<std::size_t>(k)]];
    return std::array<double, 3>{p[0] - p0[0], p[1] - p0[1], p[2] - p0[2]};
  };
  const auto x = d(1), y = d(2), z = d(3);
  return x[0] * (y[1] * z[2] - y[2] * z[1]) - x[1] * (y[0] * z[2] - y[2] * z[0]) + x[2] * (y[0] * z[1] - y[1] * z[0]);
}

void add_tet(IndexedMesh& m, std::array<std::uint32_t, 4> t, std::int32_t tag) {
  if (signed_volume(m, t) < 0) std::swap(t[1], t[2]);
  m.add_cell(CellType::tetrahedron, t, tag);
}

// Appends `part`'s cells with tag `tag`; returns its first point's index.
std::uint32_t append_tagged(IndexedMesh& m, IndexedMesh part, std::int32_t tag) {
  for (auto& t : part.tags) t = tag;
  return append(m, part);
}

// Frisbee: the polar disc (centre, rings of 8k points, k = 1..8) as nylon cloth, its rim ring
// as a closed rod: 289 points, 512 triangles, 64 rod edges.
PaperShape frisbee() {
  PaperShape s;
  IndexedMesh& m = s.mesh;
  append_tagged(m, disc(0.135, 8, 8), 1);
  std::vector<std::uint32_t> rim(64);
  std::iota(rim.begin(), rim.end(), m.num_points() - 64);
  rim.push_back(rim.front());
  add_chain(m, rim, 2);
  s.names = {{shell, 1, "cloth"}, {rod, 2, "rim"}};
  s.note = "exact: polar disc 1 + 8(1 + ... + 8) points, 8(2k - 1) triangles per ring, rim = 64 rod edges";
  return s;
}

// Umbrella: a spherical canopy (radius of curvature 0.6 m, polar angles 0.03 to 0.95 rad),
// 33 rings of 96 points joined by quads split in two; 6 ribs on every 16th spoke and 6 hub
// edges joining the rib roots across the top hole (triple joints at the roots).
PaperShape umbrella() {
  PaperShape s;
  IndexedMesh& m = s.mesh;
  constexpr std::uint32_t around = 96, radial = 32;
  const double R = 0.6, a0 = 0.03, a1 = 0.95;
  const auto v = split_quad_band(m, radial + 1, around, [&](std::uint32_t j, std::uint32_t i) {
    const double phi = a0 + (a1 - a0) * j / radial, th = 2 * pi * i / around;
    return Point3{R * std::sin(phi) * std::cos(th), R * std::sin(phi) * std::sin(th), R * std::cos(phi)};
  }, 1);
  for (std::uint32_t r = 0; r < 6; ++r) {
    std::vector<std::uint32_t> rib;
    for (std::uint32_t j = 0; j <= radial; ++j) rib.push_back(v(j, 16 * r));
    add_chain(m, rib, 2);
    m.add_cell(CellType::segment, {v(0, 16 * r), v(0, 16 * (r + 1))}, 3);
  }
  s.names = {{shell, 1, "canopy"}, {rod, 2, "ribs"}, {rod, 3, "hub"}};
  s.note = "exact: 96 x 33 points, 2 x 96 x 32 triangles, 6 x 32 rib edges + 6 hub edges";
  return s;
}

// Sticky hand: a disc of rings of 8, 14, 20, 30, 40 points inside and 68 on the outline
// (181 points, 292 triangles), shaped into a palm with five fingers, in the xz plane with the
// wrist up; a 19-edge string rises from the wrist (one shared point).
PaperShape sticky_hands() {
  PaperShape s;
  IndexedMesh& m = s.mesh;
  const double palm = 0.025;
  auto outline = [&](double rho, double th) {
    double bump = 0;
    for (const double f : {-1.2, -0.6, 0.0, 0.6, 1.2}) {
      const double d = std::remainder(th - (-pi / 2 + f), 2 * pi);
      bump += std::exp(-(d / 0.16) * (d / 0.16));
    }
    const double r = rho * palm * (1 + rho * rho * bump);
    return Point3{r * std::cos(th), 0.0, r * std::sin(th)};
  };
  const auto rings = ring_disc(m, {8, 14, 20, 30, 40, 68}, outline, 1);
  const std::uint32_t wrist = rings.back()[17];  // angle π/2: the top of the outline
  const Point3 w = m.points[wrist];
  add_rod(m, wrist, 19, [&](double t) { return Point3{w[0], 0.0, w[2] + 0.19 * t}; }, 2);
  s.names = {{shell, 1, "hand"}, {rod, 2, "string"}};
  s.note = "exact: 181 hand points (68 on the outline), 292 triangles, 19 string edges";
  return s;
}

// A ball of 2n tetrahedra around its centre: an n-gon equator and two poles (n + 3 points).
void add_bipyramid(IndexedMesh& m, const Point3& c, double r, std::uint32_t n, std::int32_t tag) {
  const std::uint32_t centre = add_point(m, c);
  const std::uint32_t top = add_point(m, {c[0], c[1], c[2] + r}), bottom = add_point(m, {c[0], c[1], c[2] - r});
  const std::uint32_t e0 = m.num_points();
  for (std::uint32_t i = 0; i < n; ++i)
    add_point(m, {c[0] + r * std::cos(2 * pi * i / n), c[1] + r * std::sin(2 * pi * i / n), c[2]});
  for (std::uint32_t i = 0; i < n; ++i) {
    const std::uint32_t a = e0 + i, b = e0 + (i + 1) % n;
    add_tet(m, {centre, a, b, top}, tag);
    add_tet(m, {centre, b, a, bottom}, tag);
  }
}

// Jellyfish: a thin body disc (radius 0.1 m, 2 cm thick: 2 layers of 91 points, 432 tets), an
// eyeball (22 tets, 14 points) on a 13-edge stalk from the body's top centre, 3 oral-arm loops
// of 40 edges between bottom points, 12 tentacles of 95 edges from every third rim point.
PaperShape jellyfish() {
  PaperShape s;
  IndexedMesh& m = s.mesh;
  append_tagged(m, cylinder(0.1, 0.02, 4, 9, 1), 1);  // bottom layer points 0..90, top 91..181
  const std::uint32_t top_centre = 91;
  const Point3 eye_c{0, 0, 0.02 + 0.06 + 0.015};
  add_bipyramid(m, eye_c, 0.015, 11, 2);
  const std::uint32_t eye_bottom = top_centre + 91 + 2;  // the eyeball's second point
  add_rod(m, top_centre, 13, [](double t) { return Point3{0.004 * std::sin(pi * t), 0, 0.02 + 0.06 * t}; }, 5, eye_bottom);
  for (std::uint32_t a = 0; a < 3; ++a) {  // bottom ring 2 (18 points from 10): loops across 3 points
    const std::uint32_t p = 10 + 6 * a, q = p + 3;
    const Point3 P = m.points[p], Q = m.points[q];
    add_rod(m, p, 40, [&](double t) {
      return Point3{P[0] + (Q[0] - P[0]) * t, P[1] + (Q[1] - P[1]) * t, -0.12 * std::sin(pi * t)};
    }, 4, q);
  }
  for (std::uint32_t k = 0; k < 12; ++k) {  // bottom rim: ring 4, 36 points from 55
    const std::uint32_t p = 55 + 3 * k;
    const Point3 P = m.points[p];
    add_rod(m, p, 95, [&](double t) {
      const double out = 1 + 0.15 * t;
      return Point3{P[0] * out, P[1] * out, -0.38 * t};
    }, 3);
  }
  s.names = {{solid, 1, "body"}, {solid, 2, "eye"}, {rod, 3, "tentacles"}, {rod, 4, "arms"}, {rod, 5, "stalk"}};
  s.note = "exact: 182 + 14 solid points, 432 + 22 tets; 13 + 3 x 40 + 12 x 95 = 1273 rod edges, 12 + 117 + 1140 own points";
  return s;
}

// Toy ball (proxy): a 96-triangle platform (disc of 4 rings of 6k points), a ball of the 226
// tetrahedra nearest its centre in a 4³-cube grid (6 tets per cube), and a 203-edge helical
// spring from the platform's centre to the ball's lowest point. The spring is short and wide
// (4 turns of 4 cm diameter over 8 cm) so that it carries the ball without buckling: a helical
// spring buckles as a column at a compression proportional to D²/L, whatever its wire
// (docs/paper_scenes.md, "The toy ball's spring").
PaperShape toy_ball() {
  constexpr double spring_length = 0.08, coil_radius = 0.02, turns = 4, ball_radius = 0.02;
  PaperShape s;
  IndexedMesh& m = s.mesh;
  append_tagged(m, disc(0.04, 4, 6), 1);
  GridSpec g;
  g.spacing = {0.01, 0.01, 0.01};
  g.origin = {-ball_radius, -ball_radius, spring_length};
  const IndexedMesh grid = tet_grid(4, 4, 4, TetSplit::kuhn6, g);
  const Point3 c{0, 0, spring_length + ball_radius};
  std::vector<std::pair<double, std::uint32_t>> by_distance;
  for (std::uint32_t t = 0; t < grid.num_cells(); ++t) {
    Point3 mid{0, 0, 0};
    for (const std::uint32_t p : grid.cell(t))
      for (int k = 0; k < 3; ++k) mid[k] += grid.points[p][k] / 4;
    by_distance.push_back({std::hypot(mid[0] - c[0], mid[1] - c[1], mid[2] - c[2]), t});
  }
  std::sort(by_distance.begin(), by_distance.end());
  std::vector<std::uint32_t> new_index(grid.num_points(), ~0u);
  std::uint32_t lowest = ~0u;
  for (std::size_t k = 0; k < 226; ++k) {
    std::array<std::uint32_t, 4> t{};
    for (std::size_t i = 0; i < 4; ++i) {
      const std::uint32_t p = grid.cell(by_distance[k].second)[i];
      if (new_index[p] == ~0u) new_index[p] = add_point(m, grid.points[p]);
      t[i] = new_index[p];
    }
    m.add_cell(CellType::tetrahedron, t, 2);
  }
  for (std::uint32_t p = 61; p < m.num_points(); ++p) {  // lowest, then nearest the axis
    auto key = [&](std::uint32_t q) { return std::pair(m.points[q][2], std::hypot(m.points[q][0], m.points[q][1])); };
    if (lowest == ~0u || key(p) < key(lowest)) lowest = p;
  }
  const Point3 end = m.points[lowest];
  add_rod(m, 0, 203, [&](double t) {
    const double r = coil_radius * std::min({1.0, t / 0.05, (1 - t) / 0.05}), a = 2 * pi * turns * t;
    return Point3{end[0] * t + r * std::cos(a), end[1] * t + r * std::sin(a), end[2] * t};
  }, 3, lowest);
  s.names = {{shell, 1, "platform"}, {solid, 2, "ball"}, {rod, 3, "spring"}};
  s.note = "proxy: 96 triangles, 226 tets, 203 rod edges as published; points differ (a 203-edge rod alone needs 202 of the 229)";
  return s;
}

// Sandwich (proxy): a beam of 10 × 2 × 5 cubes of 3 × 3 × 1 cm, 6 tets each (600), whose 4
// interior horizontal face layers (z = 1, ..., 4 cm) are stiff shells: 160 triangles.
PaperShape sandwich() {
  PaperShape s;
  IndexedMesh& m = s.mesh;
  GridSpec g;
  g.spacing = {0.03, 0.03, 0.01};
  append_tagged(m, tet_grid(10, 2, 5, TetSplit::kuhn6, g), 1);
  std::set<std::array<std::uint32_t, 3>> seen;
  const std::uint32_t tets = m.num_cells();
  for (std::uint32_t t = 0; t < tets; ++t) {
    const auto c = m.cell(t);
    for (std::size_t skip = 0; skip < 4; ++skip) {
      std::array<std::uint32_t, 3> f{};
      for (std::size_t i = 0, k = 0; i < 4; ++i)
        if (i != skip) f[k++] = c[i];
      const double z = m.points[f[0]][2];
      const int layer = static_cast<int>(std::lround(z / 0.01));
      if (layer < 1 || layer > 4 || std::abs(m.points[f[1]][2] - z) > 1e-9 || std::abs(m.points[f[2]][2] - z) > 1e-9) continue;
      std::array<std::uint32_t, 3> key = f;
      std::sort(key.begin(), key.end());
      if (seen.insert(key).second) m.add_cell(CellType::triangle, {f[0], f[1], f[2]}, 2);
    }
  }
  s.names = {{solid, 1, "core"}, {shell, 2, "sheets"}};
  s.note = "proxy: 600 tets as published, 198 points and 160 shell triangles (1510 cannot lie in 600 tets)";
  return s;
}

// Toy tunnel (Fig. 14; no published counts): a cylindrical cloth along x (radius 8 cm, 45 cm
// long, lying 2 cm above z = 0), 30 rings of 20 quads each split along the diagonal (j, i)–(j + 1, i + 1), so that the
// diagonals form helices; two of them (half a turn apart, 30 edges and 1.5 turns each) are rods:
// the paper's spiral of existing edges labelled as rods. 620 points, 1200 triangles, 60 rod edges.
PaperShape toy_tunnel() {
  PaperShape s;
  IndexedMesh& m = s.mesh;
  constexpr std::uint32_t around = 20, along = 30;
  const double r = 0.08, length = 0.45, lift = 0.02;
  const auto v = split_quad_band(m, along + 1, around, [&](std::uint32_t j, std::uint32_t i) {
    const double th = 2 * pi * i / around;
    return Point3{length * j / along, r * std::cos(th), lift + r + r * std::sin(th)};
  }, 1);
  for (const std::uint32_t start : {0u, around / 2}) {
    std::vector<std::uint32_t> helix;
    for (std::uint32_t j = 0; j <= along; ++j) helix.push_back(v(j, start + j));
    add_chain(m, helix, 2);
  }
  s.names = {{shell, 1, "cloth"}, {rod, 2, "spiral"}};
  s.note = "from the figure (no published counts): 20 x 31 points, 2 x 20 x 30 triangles, 2 helices of 30 diagonal edges as rods";
  return s;
}

// Anglerfish (Fig. 17; no published counts): a body of tetrahedra (a 6 × 4 × 4 grid of
// 2 × 1.5 × 1.5 cm cells, 6 tets each: 576), fins of triangles joined to it along rows of its
// edges (curve connections): a dorsal fin on the top's middle line, a tail fin on the back face's,
// a pectoral fin on each side; a 20-edge antenna (rod) arching forward from the top of the head,
// point-joined to the body and, at its tip, to a light ball (tetrahedra, 16).
PaperShape anglerfish() {
  PaperShape s;
  IndexedMesh& m = s.mesh;
  GridSpec g;
  g.spacing = {0.02, 0.015, 0.015};
  append_tagged(m, tet_grid(6, 4, 4, TetSplit::kuhn6, g), 1);
  auto body = [](std::uint32_t i, std::uint32_t j, std::uint32_t k) { return i + 7 * (j + 5 * k); };
  // A fin of `rows` rows of triangles on the root points (a row of body edges): each row's
  // points are the last row's moved by step(row) (one fewer per row, a tapering fin).
  auto fin = [&](std::vector<std::uint32_t> root, std::uint32_t rows, const std::function<Point3(const Point3&, std::uint32_t)>& step) {
    for (std::uint32_t row = 1; row <= rows && root.size() > 1; ++row) {
      std::vector<std::uint32_t> next;
      for (std::size_t q = 0; q + 1 < root.size(); ++q) {
        const Point3 a = m.points[root[q]], b = m.points[root[q + 1]];
        next.push_back(add_point(m, step({(a[0] + b[0]) / 2, (a[1] + b[1]) / 2, (a[2] + b[2]) / 2}, row)));
      }
      for (std::size_t q = 0; q + 1 < root.size(); ++q) {
        m.add_cell(CellType::triangle, {root[q], root[q + 1], next[q]}, 2);
        if (q + 1 < next.size()) m.add_cell(CellType::triangle, {next[q], root[q + 1], next[q + 1]}, 2);
      }
      root = std::move(next);
    }
  };
  std::vector<std::uint32_t> dorsal, tail, left, right;
  for (std::uint32_t i = 1; i <= 4; ++i) dorsal.push_back(body(i, 2, 4));
  for (std::uint32_t k = 0; k <= 4; ++k) tail.push_back(body(0, 2, k));
  for (std::uint32_t i = 2; i <= 5; ++i) left.push_back(body(i, 0, 2)), right.push_back(body(i, 4, 2));
  fin(dorsal, 3, [](const Point3& p, std::uint32_t) { return Point3{p[0] - 0.006, p[1], p[2] + 0.012}; });
  fin(tail, 4, [](const Point3& p, std::uint32_t) { return Point3{p[0] - 0.012, p[1], p[2] + (p[2] - 0.03) * 0.25}; });
  fin(left, 2, [](const Point3& p, std::uint32_t) { return Point3{p[0] - 0.006, p[1] - 0.012, p[2] - 0.003}; });
  fin(right, 2, [](const Point3& p, std::uint32_t) { return Point3{p[0] - 0.006, p[1] + 0.012, p[2] - 0.003}; });
  // the light ball's lowest pole ends the antenna: it arcs up from the head's top front edge
  const std::uint32_t head = body(6, 2, 4);
  const Point3 h = m.points[head];
  const Point3 ball{h[0] + 0.05, h[1], h[2] + 0.02 + 0.008};
  const std::uint32_t pole = m.num_points() + 2;  // add_bipyramid: centre, top, bottom, ...
  add_bipyramid(m, ball, 0.008, 8, 4);
  add_rod(m, head, 20, [&](double t) {
    const double a = pi * t;  // a half ellipse over the head, ending under the ball
    return Point3{h[0] + 0.025 - 0.025 * std::cos(a), h[1], h[2] + 0.06 * std::sin(a) + 0.02 * t};
  }, 3, pole);
  s.names = {{solid, 1, "body"}, {shell, 2, "fins"}, {rod, 3, "antenna"}, {solid, 4, "light"}};
  s.note = "from the figure (no published counts): 576 body tets, 41 fin triangles on 3 + 4 + 3 + 3 body edges, a 20-edge antenna, a 16-tet light ball";
  return s;
}

}  // namespace

const std::vector<std::string>& paper_shape_names() {
  static const std::vector<std::string> names{"frisbee", "umbrella", "sticky_hands", "jellyfish", "toy_ball", "sandwich",
                                                   "toy_tunnel", "anglerfish"};
  return names;
}

IndexedMesh fig18_slab(std::uint32_t solid, std::uint32_t shell, std::uint32_t ny, std::uint32_t nz, double cell) {
  GridSpec grid;
  grid.spacing = {cell, cell, cell};
  IndexedMesh m = tet_grid(solid, ny, nz, TetSplit::kuhn6, grid);
  for (auto& t : m.tags) t = 1;
  std::vector<std::uint32_t> prev(ny + 1), cur(ny + 1);
  for (std::uint32_t j = 0; j <= ny; ++j) prev[j] = solid + (solid + 1) * (j + (ny + 1) * (nz / 2));
  for (std::uint32_t i = 1; i <= shell; ++i) {
    for (std::uint32_t j = 0; j <= ny; ++j) cur[j] = add_point(m, {(solid + i) * cell, j * cell, nz / 2 * cell});
    for (std::uint32_t j = 0; j < ny; ++j) {
      m.add_cell(CellType::triangle, {prev[j], cur[j], cur[j + 1]}, 2);
      m.add_cell(CellType::triangle, {prev[j], cur[j + 1], prev[j + 1]}, 2);
    }
    prev = cur;
  }
  return m;
}

PaperShape make_paper_shape(const std::string& name) {
  if (name == "frisbee") return frisbee();
  if (name == "umbrella") return umbrella();
  if (name == "sticky_hands") return sticky_hands();
  if (name == "jellyfish") return jellyfish();
  if (name == "toy_ball") return toy_ball();
  if (name == "sandwich") return sandwich();
  if (name == "toy_tunnel") return toy_tunnel();
  if (name == "anglerfish") return anglerfish();
  std::string known;
  for (const auto& n : paper_shape_names()) known += (known.empty() ? "" : ", ") + n;
  throw std::invalid_argument("no paper shape '" + name + "' (known: " + known + ")");
}

}  // namespace sewn::app
