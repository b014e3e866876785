// bench_elastic (issue 15). Cases, all "ours":
//   elastic/cantilever/N<n>/<solver>   static tip of the 1 m × 0.1 m × 0.1 m cantilever
//       (E = 100 MPa, ν = 0.3, ρ = 1000, g = 9.81, clamped at x = 0; 10N×N×N cubes of 6 Kuhn
//       tetrahedra, StVK) by one quasi-static Newton step (h = 1e3 s, so inertia weighs ~1e-9 of
//       the stiffness); time of the solve, tip (mean z of the x = L nodes) and its error against
//       Timoshenko's 14.868 mm (PHYSICS_NOTES §4), Newton and CG iterations.
//   elastic/step/N<n>/<solver>         one dynamic step (h = 10 ms) of the same beam swinging,
//       ms per step and per Newton iteration.
//   elastic/cantilever/static/N<n>/ours, elastic/cantilever/N<n>/implicit_h1e-2/ours
//       the same beam as the mass-spring system of bench/mss (cubes of springs, the 2013
//       paper's stiffnesses), its static tip and a run to rest (register_cantilever_springs).
// The runs from release to rest of the tets, the shell strip and a rod (cost per simulated
// second) are in to_rest.cpp; the static rows of the strip and the rod in shell_strip.cpp and
// rod_elastica.cpp.
#include <cmath>
#include <ctime>
#include <string>
#include <vector>

#include <Eigen/Geometry>

#include "sewn/physics/basic_terms.hpp"
#include "sewn/physics/integrate/newton_euler.hpp"
#include "sewn/physics/solids/tets.hpp"
#include "cantilever.hpp"
#include "tet_cantilever.hpp"
#include "sewn_bench.hpp"

namespace {

using namespace sewn::physics;
using Eigen::Vector3d;

using sewn::tet_cantilever::Beam;
using sewn::tet_cantilever::build;
using sewn::tet_cantilever::timoshenko_mm;
using sewn::tet_cantilever::tip_mm;

const char* name(integrate::LinearSolver s) { return s == integrate::LinearSolver::cg ? "cg" : "ldlt"; }

void static_solve(benchmark::State& st, int n, integrate::LinearSolver solver) {
  double tip = 0.0;
  int newton = 0, linear = 0;
  double dof = 0.0;
  for (auto _ : st) {
    Beam beam;
    {
      sewn::bench::Untimed pause(st);
      build(beam, n);
      dof = 3.0 * beam.sys.nodes().num_alive();
    }
    const double h = 1e3;
    integrate::NewtonEulerOptions opt;
    opt.solver = solver;
    opt.velocity_tolerance = 1e-9 / h;  // |p|∞ below 1 nm
    opt.cg_tolerance = 1e-6;
    opt.cg_max_iterations = 100000;
    integrate::NewtonEuler newton_euler(opt);
    try {
      const auto rep = newton_euler.step(beam.sys, h);
      newton = rep.iterations;
      linear = rep.linear_iterations;
    } catch (const std::exception& e) {
      st.SkipWithError((std::string("cantilever N=") + std::to_string(n) + ": " + e.what()).c_str());
      return;
    }
    tip = tip_mm(beam);
  }
  st.counters["tip mm"] = tip;
  st.counters["error vs Timoshenko %"] = 100.0 * std::abs(tip - timoshenko_mm) / timoshenko_mm;
  st.counters["Newton iterations"] = newton;
  st.counters["linear iterations"] = linear;
  st.counters["_dof"] = dof;
  st.counters["_n"] = n;
}

void dynamic_step(benchmark::State& st, int n, integrate::LinearSolver solver) {
  Beam beam;
  build(beam, n);
  integrate::NewtonEulerOptions opt;
  opt.solver = solver;
  opt.velocity_tolerance = 1e-6;
  integrate::NewtonEuler newton_euler(opt);
  const double h = 1e-2;
  // Start mid-swing: a few steps from rest so the step is a real nonlinear solve.
  for (int k = 0; k < 3; ++k) (void)newton_euler.step(beam.sys, h);
  double iterations = 0.0, steps = 0.0, linear = 0.0, cpu = 0.0;
  for (auto _ : st) {
    try {
      const std::clock_t t0 = std::clock();
      const auto rep = newton_euler.step(beam.sys, h);
      cpu += static_cast<double>(std::clock() - t0) / CLOCKS_PER_SEC;
      iterations += rep.iterations;
      linear += rep.linear_iterations;
      steps += 1.0;
    } catch (const std::exception& e) {
      st.SkipWithError((std::string("step N=") + std::to_string(n) + ": " + e.what()).c_str());
      return;
    }
  }
  st.counters["Newton iterations per step"] = iterations / steps;
  st.counters["linear iterations per step"] = linear / steps;
  st.counters["ms per Newton iteration"] = iterations > 0 ? 1e3 * cpu / iterations : 0.0;
  st.counters["_vertices"] = beam.sys.nodes().num_alive();
}

void register_all() {
  using sewn::bench::Scale;
  const Scale scale = sewn::bench::scale();
  std::vector<int> sizes = scale == Scale::smoke ? std::vector<int>{1} : scale == Scale::small ? std::vector<int>{1, 2}
                                                                                                 : std::vector<int>{1, 2, 4};
  for (const auto solver : {integrate::LinearSolver::ldlt, integrate::LinearSolver::cg})
    for (int n : sizes)
      sewn::bench::ours("elastic", "cantilever/N" + std::to_string(n) + "/" + name(solver),
                        [n, solver](benchmark::State& st) { static_solve(st, n, solver); })
          ->Iterations(1);
  if (scale == Scale::full)
    sewn::bench::ours("elastic", "cantilever/N8/ldlt",
                      [](benchmark::State& st) { static_solve(st, 8, integrate::LinearSolver::ldlt); })
        ->Iterations(1);
  for (const auto solver : {integrate::LinearSolver::ldlt, integrate::LinearSolver::cg})
    for (int n : sizes)
      sewn::bench::ours("elastic", "step/N" + std::to_string(n) + "/" + name(solver),
                        [n, solver](benchmark::State& st) { dynamic_step(st, n, solver); });
  sewn::bench::mss::register_cantilever_springs("elastic", scale);
}

const sewn::bench::Registration reg(&register_all);

}  // namespace
