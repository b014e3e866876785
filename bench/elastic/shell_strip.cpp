// bench_elastic, the shell against its continuum answer (issue 15, step 3):
//   elastic/shell_strip/<mesh>/nx<n>   static tip of a plate strip (L = 1 m, b = 0.1 m,
//       t = 0.01 m, E = 200 GPa, ν = 0, ρ = 1000, g = 9.81) clamped at x = 0 and loaded by its
//       own weight, as CST membranes + hinges with k_B = D/6 (lumped masses), by one
//       quasi-static Newton step; against Euler–Bernoulli's δ = qL⁴/(8EI) = 0.73575 mm (ν = 0:
//       no anticlastic coupling, narrow and wide strips share the answer). Meshes: `square`,
//       nx × nx/10 square cells; `row`, one row of nx cells (elongated triangles, aspect nx/10).
//       Two triangles per cell, all diagonals one way. The clamp holds the columns x = 0 and
//       x = −L/nx, which fixes the slope at x = 0.
#include <array>
#include <cmath>
#include <string>
#include <vector>

#include "sewn/physics/basic_terms.hpp"
#include "sewn/physics/integrate/newton_euler.hpp"
#include "sewn/physics/shells/shell_terms.hpp"
#include "sewn_bench.hpp"

namespace bench_shell_strip {
namespace {

using sewn::physics::Index;
using Eigen::Vector3d;

constexpr double E = 2e11, rho = 1000.0, g = 9.81, L = 1.0, b = 0.1, t = 0.01;

// Euler–Bernoulli's tip under the weight q = ρ g b t, EI = E b t³/12.
double euler_bernoulli_m() {
  const double q = rho * g * b * t, EI = E * b * t * t * t / 12;
  return q * L * L * L * L / (8 * EI);
}

struct Strip {
  sewn::physics::System sys;
  std::vector<Index> tip;
};

void build(Strip& s, int nx, int ny) {
  const double a = L / nx;
  const int cols = nx + 2;  // x = −a, 0, a, ..., L
  auto id = [&](int i, int j) { return static_cast<Index>(i + cols * j); };
  std::vector<double> rest;
  for (int j = 0; j <= ny; ++j)
    for (int i = 0; i < cols; ++i) rest.insert(rest.end(), {a * (i - 1), (b / ny) * j, 0.0});
  std::vector<std::array<Index, 3>> tris;
  for (int j = 0; j < ny; ++j)
    for (int i = 0; i + 1 < cols; ++i) {
      tris.push_back({id(i, j), id(i + 1, j), id(i + 1, j + 1)});
      tris.push_back({id(i, j), id(i + 1, j + 1), id(i, j + 1)});
    }
  const Index n = static_cast<Index>(rest.size() / 3);
  std::vector<double> mass(n, 0.0);
  const double corner_mass = rho * t * (a * b / ny / 2) / 3;  // a third of each triangle
  for (const auto& tr : tris)
    for (Index v : tr) mass[v] += corner_mass;
  for (Index i = 0; i < n; ++i) s.sys.nodes().add(Vector3d(rest[3 * i], rest[3 * i + 1], rest[3 * i + 2]), Vector3d::Zero(), mass[i]);
  auto& membranes = s.sys.add<sewn::physics::shells::Membranes>();
  for (const auto& tr : tris) {
    sewn::physics::shells::TriPositions X;
    for (int c = 0; c < 3; ++c) X.col(c) = s.sys.nodes().position(tr[static_cast<std::size_t>(c)]);
    membranes.add(tr, X, E, 0.0, t);
  }
  s.sys.add<sewn::physics::shells::Hinges>().add_interior_edges(tris, rest, sewn::physics::shells::hinge_stiffness(E, 0.0, t));
  s.sys.add<sewn::physics::Gravity>(Vector3d(0, 0, -g));
  for (Index i = 0; i < n; ++i) {
    if (rest[3 * i] <= 1e-12) s.sys.nodes().fix(i);
    if (std::abs(rest[3 * i] - L) < 1e-12) s.tip.push_back(i);
  }
}

void strip_tip(benchmark::State& st, int nx, int ny) {
  double tip = 0.0;
  int newton = 0;
  for (auto _ : st) {
    Strip s;
    {
      sewn::bench::Untimed pause(st);
      build(s, nx, ny);
    }
    const double h = 1e3;  // inertia M/h² ~1e-12 of the bending stiffness
    sewn::physics::integrate::NewtonEulerOptions opt;
    opt.solver = sewn::physics::integrate::LinearSolver::ldlt;
    opt.velocity_tolerance = 1e-13 / h;  // |p|∞ below 1e-13 m
    sewn::physics::integrate::NewtonEuler newton_euler(opt);
    try {
      newton = newton_euler.step(s.sys, h).iterations;
    } catch (const std::exception& e) {
      st.SkipWithError((std::string("shell strip nx=") + std::to_string(nx) + ": " + e.what()).c_str());
      return;
    }
    double z = 0;
    for (Index i : s.tip) z += s.sys.nodes().position(i).z();
    tip = -z / static_cast<double>(s.tip.size());
  }
  const double exact = euler_bernoulli_m();
  st.counters["tip mm"] = 1e3 * tip;
  st.counters["Euler-Bernoulli mm"] = 1e3 * exact;
  st.counters["error vs Euler-Bernoulli %"] = 100.0 * std::abs(tip - exact) / exact;
  st.counters["Newton iterations"] = newton;
  st.counters["_triangles"] = 2.0 * (nx + 1) * ny;
}

void register_all() {
  using sewn::bench::Scale;
  const Scale scale = sewn::bench::scale();
  const std::vector<int> sizes = scale == Scale::smoke ? std::vector<int>{10} : scale == Scale::small ? std::vector<int>{10, 20, 40}
                                                                                                       : std::vector<int>{10, 20, 40, 80};
  for (int nx : sizes) {
    sewn::bench::ours("elastic", "shell_strip/square/nx" + std::to_string(nx),
                      [nx](benchmark::State& st) { strip_tip(st, nx, nx / 10); })
        ->Iterations(1);
    sewn::bench::ours("elastic", "shell_strip/row/nx" + std::to_string(nx), [nx](benchmark::State& st) { strip_tip(st, nx, 1); })
        ->Iterations(1);
  }
}

const sewn::bench::Registration reg(&register_all);

}  // namespace
}  // namespace bench_shell_strip
