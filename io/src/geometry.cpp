#include "sewn/io/geometry.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <limits>
#include <span>

namespace sewn::io {

namespace {

using V3 = std::array<double, 3>;

V3 sub(const Point3& a, const Point3& b) { return {a[0] - b[0], a[1] - b[1], a[2] - b[2]}; }
V3 cross(const V3& a, const V3& b) {
  return {a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]};
}
double dot(const V3& a, const V3& b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }
double norm(const V3& a) { return std::sqrt(dot(a, a)); }

// Corner c, then the three neighbours whose edge vectors form a positive frame at c for a
// positively oriented cell in VTK order (derived from the outward face tables in mesh.cpp).
constexpr std::array<std::array<std::uint32_t, 4>, 4> tet_corners{{{0, 1, 2, 3}, {1, 2, 0, 3}, {2, 0, 1, 3}, {3, 0, 2, 1}}};
constexpr std::array<std::array<std::uint32_t, 4>, 8> hex_corners{{{0, 1, 3, 4},
                                                                   {1, 2, 0, 5},
                                                                   {2, 3, 1, 6},
                                                                   {3, 0, 2, 7},
                                                                   {4, 7, 5, 0},
                                                                   {5, 4, 6, 1},
                                                                   {6, 5, 7, 2},
                                                                   {7, 6, 4, 3}}};
constexpr std::array<std::array<std::uint32_t, 4>, 6> prism_corners{
    {{0, 2, 1, 3}, {1, 0, 2, 4}, {2, 1, 0, 5}, {3, 4, 5, 0}, {4, 5, 3, 1}, {5, 3, 4, 2}}};
// The apex of a pyramid has four edges, so no single frame; the four base corners decide.
constexpr std::array<std::array<std::uint32_t, 4>, 4> pyramid_corners{{{0, 1, 3, 4}, {1, 2, 0, 4}, {2, 3, 1, 4}, {3, 0, 2, 4}}};

std::span<const std::array<std::uint32_t, 4>> corners_of(CellType t) {
  switch (t) {
    case CellType::tetrahedron: return tet_corners;
    case CellType::hexahedron: return hex_corners;
    case CellType::prism: return prism_corners;
    case CellType::pyramid: return pyramid_corners;
    default: return {};
  }
}

double scaled_det(const Point3& c, const Point3& a, const Point3& b, const Point3& d) {
  const V3 e1 = sub(a, c), e2 = sub(b, c), e3 = sub(d, c);
  const double l = norm(e1) * norm(e2) * norm(e3);
  if (!(l > 0)) return 0.0;
  return dot(cross(e1, e2), e3) / l;
}

// Per-corner measures of a cell: scaled Jacobians (3D), scaled corner areas (2D, relative to
// the cell's mean normal for quads), or the length (1D, unscaled).
std::vector<double> corner_values(const IndexedMesh& m, std::uint32_t cell) {
  const auto v = m.cell(cell);
  const auto& P = m.points;
  std::vector<double> r;
  switch (m.types[cell]) {
    case CellType::segment: r.push_back(norm(sub(P[v[1]], P[v[0]]))); break;
    case CellType::triangle: {
      for (std::size_t i = 0; i < 3; ++i) {
        const V3 a = sub(P[v[(i + 1) % 3]], P[v[i]]), b = sub(P[v[(i + 2) % 3]], P[v[i]]);
        const double l = norm(a) * norm(b);
        r.push_back(l > 0 ? norm(cross(a, b)) / l : 0.0);
      }
      break;
    }
    case CellType::quad: {
      const V3 n = cross(sub(P[v[2]], P[v[0]]), sub(P[v[3]], P[v[1]]));
      const double nn = norm(n);
      for (std::size_t i = 0; i < 4; ++i) {
        const V3 a = sub(P[v[(i + 1) % 4]], P[v[i]]), b = sub(P[v[(i + 3) % 4]], P[v[i]]);
        const double l = norm(a) * norm(b) * nn;
        r.push_back(l > 0 ? dot(cross(a, b), n) / l : 0.0);
      }
      break;
    }
    default:
      for (const auto& c : corners_of(m.types[cell])) r.push_back(scaled_det(P[v[c[0]]], P[v[c[1]]], P[v[c[2]]], P[v[c[3]]]));
  }
  return r;
}

std::string fmt(double x) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.6g", x);
  return buf;
}

// Point `p` as the options number it (the file's number when given).
std::string point_number(const GeometryOptions& opt, std::uint32_t p) {
  return std::to_string(opt.point_numbers.empty() ? std::int64_t{p} : opt.point_numbers[p]);
}

std::string describe_points(const IndexedMesh& m, std::span<const std::uint32_t> pts, const GeometryOptions& opt) {
  std::string s = "points";
  for (std::size_t k = 0; k < pts.size(); ++k) {
    const auto& p = m.points[pts[k]];
    s += (k ? ", " : " ") + point_number(opt, pts[k]) + " (" + fmt(p[0]) + ", " + fmt(p[1]) + ", " + fmt(p[2]) + ")";
  }
  return s;
}

std::string element_tag(const GeometryOptions& opt, std::uint32_t c) {
  return opt.element_tags.empty() ? "" : "Gmsh element " + std::to_string(opt.element_tags[c]) + ", ";
}

std::string cell_name(const IndexedMesh& m, std::uint32_t c, const GeometryOptions& opt) {
  return "cell " + std::to_string(c) + " (" + element_tag(opt, c) + to_string(m.types[c]) + ")";
}

double bbox_diagonal(const IndexedMesh& m) {
  if (m.points.empty()) return 0.0;
  V3 lo = m.points[0], hi = m.points[0];
  for (const auto& p : m.points)
    for (std::size_t k = 0; k < 3; ++k) {
      lo[k] = std::min(lo[k], p[k]);
      hi[k] = std::max(hi[k], p[k]);
    }
  return norm(sub(hi, lo));
}

}  // namespace

double min_scaled_jacobian(const IndexedMesh& mesh, std::uint32_t cell) {
  const auto v = corner_values(mesh, cell);
  return v.empty() ? 0.0 : *std::min_element(v.begin(), v.end());
}

double cell_measure(const IndexedMesh& mesh, std::uint32_t cell) {
  const auto v = mesh.cell(cell);
  const auto& P = mesh.points;
  switch (cell_dimension(mesh.types[cell])) {
    case 1: return norm(sub(P[v[1]], P[v[0]]));
    case 2: {
      V3 n{0, 0, 0};
      for (std::size_t k = 1; k + 1 < v.size(); ++k) {
        const V3 c = cross(sub(P[v[k]], P[v[0]]), sub(P[v[k + 1]], P[v[0]]));
        for (std::size_t i = 0; i < 3; ++i) n[i] += c[i];
      }
      return 0.5 * norm(n);
    }
    default: {
      // divergence theorem relative to vertex 0: sum of the tetrahedra (p0, face fan triangle)
      double vol = 0;
      for (auto f : cell_faces(mesh.types[cell])) {
        const Point3& a = P[v[f[0]]];
        for (std::size_t k = 1; k + 1 < f.size(); ++k)
          vol += dot(cross(sub(P[v[f[k]]], a), sub(P[v[f[k + 1]]], a)), sub(a, P[v[0]]));
      }
      return vol / 6.0;
    }
  }
}

std::vector<GeometryIssue> find_geometry_issues(const IndexedMesh& mesh, const std::string& source,
                                                const GeometryOptions& opt) {
  mesh.check_indices(source);
  std::vector<GeometryIssue> issues;
  auto full = [&] { return issues.size() >= opt.max_issues; };

  std::vector<std::uint32_t> first_user(mesh.num_points(), GeometryError::no_cell);
  for (std::uint32_t c = mesh.num_cells(); c-- > 0;)
    for (std::uint32_t p : mesh.cell(c)) first_user[p] = c;
  bool all_finite = true;
  for (std::uint32_t p = 0; p < mesh.num_points() && !full(); ++p) {
    const auto& x = mesh.points[p];
    if (std::isfinite(x[0]) && std::isfinite(x[1]) && std::isfinite(x[2])) continue;
    all_finite = false;
    const std::uint32_t c = first_user[p];
    GeometryIssue is{GeometryProblem::non_finite_point, c, {}, {}};
    is.message = source + ": point " + point_number(opt, p) + " has a non-finite coordinate (" + fmt(x[0]) + ", " +
                 fmt(x[1]) + ", " + fmt(x[2]) + ")";
    if (c != GeometryError::no_cell) {
      const auto v = mesh.cell(c);
      is.points.assign(v.begin(), v.end());
      is.message += "; it is used by " + cell_name(mesh, c, opt) + " with " + describe_points(mesh, v, opt);
    } else {
      is.points = {p};
    }
    issues.push_back(std::move(is));
  }
  // Cell measures of non-finite points mean nothing; those points were reported above.
  if (!all_finite) return issues;

  const double min_len = opt.min_relative_length * bbox_diagonal(mesh);
  for (std::uint32_t c = 0; c < mesh.num_cells() && !full(); ++c) {
    const CellType t = mesh.types[c];
    const auto vals = corner_values(mesh, c);
    const auto v = mesh.cell(c);
    std::string reason;
    GeometryProblem kind = GeometryProblem::degenerate;
    if (t == CellType::segment) {
      if (vals[0] <= min_len) reason = "has length " + fmt(vals[0]);
    } else {
      const double tol = opt.min_scaled_jacobian;
      std::size_t neg = 0;
      std::string bad;
      for (std::size_t k = 0; k < vals.size(); ++k) {
        if (vals[k] < -tol) ++neg;
        if (vals[k] <= tol) bad += (bad.empty() ? "" : ", ") + std::to_string(k) + " (" + fmt(vals[k]) + ")";
      }
      if (cell_dimension(t) == 3 && neg == vals.size()) {
        kind = GeometryProblem::inverted;
        reason = "is inverted: its vertex order gives a negative volume (scaled Jacobian " +
                 fmt(*std::max_element(vals.begin(), vals.end())) + " or less at every corner)";
      } else if (!bad.empty()) {
        reason = cell_dimension(t) == 3
                     ? "is degenerate or folded: scaled Jacobian not positive at local corner(s) " + bad
                     : "is degenerate" + std::string(t == CellType::quad ? " or not convex" : "") +
                           ": scaled corner area not positive at local corner(s) " + bad;
      }
    }
    if (reason.empty()) continue;
    issues.push_back({kind, c, std::vector<std::uint32_t>(v.begin(), v.end()),
                      source + ": " + cell_name(mesh, c, opt) + " " + reason + "; " + describe_points(mesh, v, opt)});
  }
  // A cell given twice (same type, same points in any order) would double its mass and stiffness
  // silently in 2D and 1D, and make the map builder fail in 3D. Sorted keys of fixed size: one
  // allocation, O(n log n).
  using Key = std::array<std::uint32_t, 10>;  // type, up to 8 sorted points padded, cell
  std::vector<Key> keys(mesh.num_cells());
  for (std::uint32_t c = 0; c < mesh.num_cells(); ++c) {
    const auto v = mesh.cell(c);
    Key& k = keys[c];
    k.fill(std::numeric_limits<std::uint32_t>::max());
    k[0] = static_cast<std::uint32_t>(mesh.types[c]);
    std::copy_n(v.begin(), std::min<std::size_t>(v.size(), 8), k.begin() + 1);
    std::sort(k.begin() + 1, k.begin() + 9);
    k[9] = c;
  }
  std::sort(keys.begin(), keys.end());
  std::vector<std::pair<std::uint32_t, std::uint32_t>> repeats;  // (cell, the first cell it repeats)
  for (std::size_t i = 1, first = 0; i < keys.size(); ++i) {
    if (!std::equal(keys[i - 1].begin(), keys[i - 1].begin() + 9, keys[i].begin())) {
      first = i;
    } else {
      repeats.emplace_back(keys[i][9], keys[first][9]);
    }
  }
  std::sort(repeats.begin(), repeats.end());
  for (const auto& [c, original] : repeats) {
    if (full()) break;
    const auto v = mesh.cell(c);
    issues.push_back({GeometryProblem::duplicate, c, std::vector<std::uint32_t>(v.begin(), v.end()),
                      source + ": " + cell_name(mesh, c, opt) + " repeats cell " + std::to_string(original) +
                          (opt.element_tags.empty() ? "" : " (Gmsh element " + std::to_string(opt.element_tags[original]) + ")") +
                          " (the same points): a duplicate cell; " + describe_points(mesh, v, opt)});
  }
  return issues;
}

void check_mesh_geometry(const IndexedMesh& mesh, const std::string& source, const GeometryOptions& opt) {
  GeometryOptions one = opt;
  one.max_issues = 1;
  const auto issues = find_geometry_issues(mesh, source, one);
  if (issues.empty()) return;
  const auto& is = issues.front();
  switch (is.kind) {
    case GeometryProblem::non_finite_point: throw NonFiniteCoordinateError(is.message, is.cell, is.points);
    case GeometryProblem::inverted: throw InvertedCellError(is.message, is.cell, is.points);
    case GeometryProblem::degenerate: throw DegenerateCellError(is.message, is.cell, is.points);
    case GeometryProblem::duplicate: throw DuplicateCellError(is.message, is.cell, is.points);
  }
}

}  // namespace sewn::io
