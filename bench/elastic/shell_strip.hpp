#pragma once
// The plate strip cantilever of PHYSICS_NOTES §4 shells (b), shared by bench_elastic's
// convergence rows and test_elastic_shells' order checks: L = 1 m, b = 0.1 m, t = 0.01 m,
// E = 200 GPa, ν = 0, ρ = 1000 kg/m³, g = 9.81 m/s², clamped at x = 0 (the columns x = 0 and
// x = -L/nx held, which fixes the slope there) and loaded by its own weight (lumped masses, a
// third of each triangle per corner); CST membranes plus a bending model (patch or Morley bending with
// the held cells as clamps); one quasi-static
// Newton step (LDLT, |p|∞ < 1e-13 m). The answer is Euler–Bernoulli's δ = qL⁴/(8EI) (ν = 0:
// no anticlastic coupling, so narrow and wide strips share it). Tip = mean z of the x = L nodes.
// Meshes (nx cells along, ny across, two triangles per cell):
//   square    ny = nx/10, every diagonal from (i, j) to (i+1, j+1);
//   flipped   the same with every diagonal from (i+1, j) to (i, j+1);
//   row       ny = 1 (triangles of aspect nx/10), diagonals as `square`;
//   jittered  ny = nx/10, inner nodes moved by up to a quarter cell in x and y and each
//             cell's diagonal drawn at random (seeded: the same mesh every run);
//   diagonals ny = nx/10, nodes on the grid, each cell's diagonal drawn at random (seeded);
//   offset    an unstructured mesh of the kind Gmsh's frontal mesher makes: rows of nodes
//             about a·√3/2 apart, every other row shifted by half a cell, inner nodes moved
//             by up to a quarter cell, and two rows zipped together by always taking the
//             shorter diagonal, so valences vary from 4 to 8 (generated here, not by Gmsh).

#include <array>
#include <cmath>
#include <cstdint>
#include <random>
#include <span>
#include <stdexcept>
#include <string>
#include <vector>

#include "sewn/physics/basic_terms.hpp"
#include "sewn/physics/integrate/newton_euler.hpp"
#include "sewn/physics/shells/morley_terms.hpp"
#include "sewn/physics/shells/patch_terms.hpp"
#include "sewn/physics/shells/shell_terms.hpp"

namespace sewn::shell_strip {

enum class Mesh { square, flipped, row, jittered, diagonals, offset };
enum class Bending { patch, hinge, morley };

inline const char* bending_name(Bending b) {
  switch (b) {
    case Bending::morley: return "morley";
    case Bending::patch: return "patch";
    case Bending::hinge: return "hinge";
  }
  return "?";
}

/// A grid cell (corners p, q, r, u counter-clockwise) as two triangles: across the diagonal p-r,
/// or across q-u when `other_diagonal`.
inline void add_cell(std::vector<std::array<physics::Index, 3>>& triangles, std::array<physics::Index, 4> c, bool other_diagonal) {
  if (other_diagonal) {
    triangles.push_back({c[0], c[1], c[3]});
    triangles.push_back({c[1], c[2], c[3]});
  } else {
    triangles.push_back({c[0], c[1], c[2]});
    triangles.push_back({c[0], c[2], c[3]});
  }
}

inline const char* mesh_name(Mesh m) {
  switch (m) {
    case Mesh::square: return "square";
    case Mesh::flipped: return "flipped";
    case Mesh::row: return "row";
    case Mesh::jittered: return "jittered";
    case Mesh::diagonals: return "diagonals";
    case Mesh::offset: return "offset";
  }
  return "?";
}

inline constexpr double young = 2e11, rho = 1000.0, gravity = 9.81, length = 1.0, width = 0.1, thickness = 0.01;

/// Euler–Bernoulli's tip under the weight q = ρ g b t, EI = E b t³/12, in m.
inline double euler_bernoulli_m() {
  const double q = rho * gravity * width * thickness, EI = young * width * thickness * thickness * thickness / 12;
  return q * length * length * length * length / (8 * EI);
}

struct Result {
  double tip_m = 0.0;
  int newton = 0;
  std::size_t triangles = 0;
};

struct Strip {
  std::vector<double> rest;  // 3 per node
  std::vector<std::array<physics::Index, 3>> triangles;
};

/// The strip's width and rows of cells (rows = 0: the mesh's own, nx/10 or 1 for `row`; not
/// used by `offset`). Euler–Bernoulli's tip does not depend on the width (ν = 0).
struct Shape {
  double width = shell_strip::width;
  int rows = 0;
};

// The `offset` mesh (see the header comment).
inline Strip offset_mesh(int nx, double strip_width = width) {
  const double a = length / nx;
  const int ny = std::max(1, static_cast<int>(std::lround(strip_width / (a * std::sqrt(3.0) / 2))));
  const double c = strip_width / ny;
  std::mt19937 rng(777u + static_cast<unsigned>(nx));
  std::uniform_real_distribution<double> jitter(-0.25, 0.25);
  Strip s;
  std::vector<std::vector<physics::Index>> rows(static_cast<std::size_t>(ny) + 1);
  for (int j = 0; j <= ny; ++j) {
    std::vector<double> xs{-a, 0.0};  // the clamp's columns, in every row
    for (int i = 1; i < nx; ++i) xs.push_back(a * i - (j % 2 == 1 ? 0.5 * a : 0.0));
    if (j % 2 == 1) xs.push_back(length - 0.5 * a);
    xs.push_back(length);
    for (double x : xs) {
      double y = c * j;
      if (x > 1e-12 && x < length - 1e-12) {
        x += a * jitter(rng);
        if (j >= 1 && j < ny) y += c * jitter(rng);
      }
      rows[static_cast<std::size_t>(j)].push_back(static_cast<physics::Index>(s.rest.size() / 3));
      s.rest.insert(s.rest.end(), {x, y, 0.0});
    }
  }
  auto at = [&](physics::Index v) { return Eigen::Vector2d(s.rest[3 * std::size_t{v}], s.rest[3 * std::size_t{v} + 1]); };
  for (std::size_t j = 0; j + 1 < rows.size(); ++j) {
    const auto& lo = rows[j];
    const auto& hi = rows[j + 1];
    std::size_t i = 0, k = 0;
    while (i + 1 < lo.size() || k + 1 < hi.size()) {
      const bool take_lo = k + 1 == hi.size() ||
                           (i + 1 < lo.size() && (at(lo[i + 1]) - at(hi[k])).norm() < (at(hi[k + 1]) - at(lo[i])).norm());
      if (take_lo) {
        s.triangles.push_back({lo[i], lo[i + 1], hi[k]});
        ++i;
      } else {
        s.triangles.push_back({lo[i], hi[k + 1], hi[k]});
        ++k;
      }
    }
  }
  return s;
}

inline Strip strip_mesh(Mesh mesh, int nx, const Shape& shape = {}) {
  if (mesh == Mesh::offset) return offset_mesh(nx, shape.width);
  const int ny = shape.rows > 0 ? shape.rows : (mesh == Mesh::row ? 1 : std::max(1, nx / 10));
  const double a = length / nx, c = shape.width / ny;
  const int cols = nx + 2;  // x = -a, 0, a, ..., L
  auto id = [&](int i, int j) { return static_cast<physics::Index>(i + cols * j); };
  std::mt19937 rng(12345u + static_cast<unsigned>(nx));
  std::uniform_real_distribution<double> jitter(-0.25, 0.25);
  Strip s;
  for (int j = 0; j <= ny; ++j)
    for (int i = 0; i < cols; ++i) {
      double x = a * (i - 1), y = c * j;
      if (mesh == Mesh::jittered) {
        if (i >= 2 && i <= nx) x += a * jitter(rng);  // the clamp's columns and the tip stay put
        if (j >= 1 && j < ny) y += c * jitter(rng);
      }
      s.rest.insert(s.rest.end(), {x, y, 0.0});
    }
  std::bernoulli_distribution coin(0.5);
  for (int j = 0; j < ny; ++j)
    for (int i = 0; i + 1 < cols; ++i) {
      const auto p = id(i, j), q = id(i + 1, j), r = id(i + 1, j + 1), u = id(i, j + 1);
      const bool other = mesh == Mesh::flipped || ((mesh == Mesh::jittered || mesh == Mesh::diagonals) && coin(rng));
      add_cell(s.triangles, {p, q, r, u}, other);
    }
  return s;
}

/// The strip as a system at rest, undeformed: nodes with lumped masses (the x ≤ 0 columns
/// held), membranes, the bending model, gravity; `tip` lists the x = L nodes.
struct Built {
  physics::System sys;
  std::vector<physics::Index> tip;
  std::size_t triangles = 0;
};

/// Nodes at the sheet's rest positions with lumped masses (ρ t Ā/3 from each triangle per
/// corner) and a CST membrane per triangle. Shared with shell_course.hpp.
inline void add_membrane_sheet(physics::System& sys, const Strip& s, double young, double poisson, double thickness,
                               double density) {
  using physics::Index;
  const Index n = static_cast<Index>(s.rest.size() / 3);
  std::vector<double> mass(n, 0.0);
  auto at = [&](Index i) { return Eigen::Vector3d(s.rest[3 * i], s.rest[3 * i + 1], s.rest[3 * i + 2]); };
  for (const auto& tr : s.triangles) {
    const double area = 0.5 * (at(tr[1]) - at(tr[0])).cross(at(tr[2]) - at(tr[0])).norm();
    for (Index v : tr) mass[v] += density * thickness * area / 3.0;
  }
  for (Index i = 0; i < n; ++i) sys.nodes().add(at(i), Eigen::Vector3d::Zero(), mass[i]);
  auto& membranes = sys.add<physics::shells::Membranes>();
  for (const auto& tr : s.triangles) {
    physics::shells::TriPositions X;
    for (int k = 0; k < 3; ++k) X.col(k) = at(tr[static_cast<std::size_t>(k)]);
    membranes.add(tr, X, young, poisson, thickness);
  }
}

/// The bending model over the sheet's triangles; patch and Morley take `clamp` (per triangle,
/// empty: none), hinges have no clamps. Shared with shell_course.hpp.
inline void add_bending(physics::System& sys, const Strip& s, Bending bending, double young, double poisson,
                        double thickness, std::span<const std::uint8_t> clamp = {}) {
  if (bending == Bending::hinge) {
    sys.add<physics::shells::Hinges>().add_interior_edges(s.triangles, s.rest,
                                                           physics::shells::hinge_stiffness(young, poisson, thickness));
    return;
  }
  const std::vector<physics::shells::PlateMaterial> mat(s.triangles.size(),
                                                        physics::shells::plate_material(young, poisson, thickness));
  if (bending == Bending::morley)
    (void)physics::shells::add_morley_bending(sys, s.triangles, s.rest, mat, clamp);
  else
    (void)physics::shells::add_patch_bending(sys, s.triangles, s.rest, mat, clamp);
}

inline void build(Built& out, Mesh mesh, Bending bending, int nx, const Shape& shape = {}) {
  using physics::Index;
  const Strip s = strip_mesh(mesh, nx, shape);
  physics::System& sys = out.sys;
  const Index n = static_cast<Index>(s.rest.size() / 3);
  add_membrane_sheet(sys, s, young, 0.0, thickness, rho);
  // patch and Morley: the cells behind x = 0 are held, clamps on the edge x = 0
  std::vector<std::uint8_t> clamp(s.triangles.size(), 0);
  for (std::size_t t = 0; t < s.triangles.size(); ++t)
    clamp[t] = s.rest[3 * std::size_t{s.triangles[t][0]}] <= 1e-12 && s.rest[3 * std::size_t{s.triangles[t][1]}] <= 1e-12 &&
               s.rest[3 * std::size_t{s.triangles[t][2]}] <= 1e-12;
  add_bending(sys, s, bending, young, 0.0, thickness, clamp);
  sys.add<physics::Gravity>(Eigen::Vector3d(0, 0, -gravity));
  for (Index i = 0; i < n; ++i) {
    if (s.rest[3 * i] <= 1e-12) sys.nodes().fix(i);
    if (std::abs(s.rest[3 * i] - length) < 1e-12) out.tip.push_back(i);
  }
  out.triangles = s.triangles.size();
}

/// The tip's deflection (mean z of the x = L nodes, positive down), in m.
inline double tip_m(const Built& b) {
  double z = 0;
  for (physics::Index i : b.tip) z += b.sys.nodes().position(i).z();
  return -z / static_cast<double>(b.tip.size());
}

/// Builds the strip with `bending`, solves it and returns the tip deflection (positive down).
/// Throws what Newton throws.
inline Result solve(Mesh mesh, Bending bending, int nx, const Shape& shape = {}) {
  Built b;
  build(b, mesh, bending, nx, shape);
  const double h = 1e3;  // inertia M/h² ~1e-12 of the bending stiffness
  physics::integrate::NewtonEulerOptions opt;
  opt.solver = physics::integrate::LinearSolver::ldlt;
  opt.velocity_tolerance = 1e-13 / h;  // |p|∞ below 1e-13 m
  physics::integrate::NewtonEuler newton(opt);
  Result r;
  r.newton = newton.step(b.sys, h).iterations;
  r.tip_m = tip_m(b);
  r.triangles = b.triangles;
  return r;
}

}  // namespace sewn::shell_strip
