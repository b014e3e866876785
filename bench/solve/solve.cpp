// bench_solve: the solver layer's backends on the implicit step (issue 14).
//
//   solve/<case>/<backend>/ours   linearly implicit Euler steps with that backend
//   solve/<case>/<backend>/peer   the same steps with block-Jacobi CG ("jacobi"), interleaved
//   solve/<case>/jacobi-ref/ours  block-Jacobi CG by the rule (relative 1e-6, no absolute
//                                 floor): the reference of the goals (bench/solve/derive)
//   solve/<case>/<backend>-nofloor/ours  cholmod-pcg, sa-pcg by that rule too (equal error)
//   solve/<case>/auto/ours        Backend::automatic, what the library picks (the goal on 32³)
//
// Each repetition starts from rest with a fresh solver and takes `steps` steps, so a backend's
// factorizations and analyses are paid inside the time it reports (ms per step). Counters per
// step: solver iterations, factorizations, and the solver's own analyse / factor / solve times.
// "error" is the position error after `error_steps` steps against a direct solve (block-Jacobi CG
// where the direct one does not run) whose every step reached a relative residual below 1e-12
// (or its round-off floor), relative to that solve's displacement (once per case,
// the same number in every repetition), "worst relative residual" the largest a step reached.
// The backends run on one thread (petsc on one MPI rank); the threads/ cases
// time 2 threads against 1 (wall time) on the semi-implicit and implicit steps of 16³ and 32³.

#include <algorithm>
#include <cmath>
#include <functional>
#include <map>
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

#include "sewn/physics/integrators.hpp"
#include "sewn/physics/mss_model.hpp"
#include "sewn/physics/solve/linear_solver.hpp"
#include "sewn/physics/threads.hpp"
#include "sewn_bench.hpp"

namespace sewn::bench::solve_suite {

namespace {

using namespace sewn::physics;
constexpr const char* suite = "solve";
const MaterialParams paper_material{100e6, 0.3, 1000};

struct Case {
  std::string name;
  std::function<std::unique_ptr<MssModel<3>>()> build;
  double h;
  int steps;        // per repetition
  int error_steps;  // for the error column
  int repetitions = 0;  // 0: the run's (bench/run.sh); fewer on the costliest cases
  // Whether the CHOLMOD backends run (direct: a factorization every step; pcg: now and then).
  // Not where one factorization costs more than the suite's budget allows: CHOLMOD's analysis
  // counts 7.1e9 flops for 16³ (~2.6 s on the reference BLAS: direct off), 2.0e11 for the N = 16
  // cantilever and 6.3e11 for 32³ (one to three minutes, 1.2-1.6 GB of factor: both off);
  // docs/solvers.md.
  bool direct = true, pcg = true;
};

std::unique_ptr<MssModel<3>> clamped(const IndexedMesh& mesh, int axis) {
  auto m = std::make_unique<MssModel<3>>(mesh, std::vector<MaterialParams>{paper_material}, std::vector<std::uint32_t>{});
  for (Index i = 0; i < m->nodes().size(); ++i)
    if (m->rest_position(i)[axis] <= 1e-12) m->nodes().fix(i);
  return m;
}

GridSpec cubes(double a) {
  GridSpec g;
  g.spacing = {a, a, a};
  return g;
}

std::vector<Case> cases(Scale scale) {
  std::vector<Case> c;
  if (scale == Scale::smoke) {
    c.push_back({"sofa/2x2x3/h1ms", [] { return clamped(hex_grid(2, 2, 3, cubes(0.0125)), 2); }, 1e-3, 3, 5});
    c.push_back({"cantilever/N2/h10ms", [] { return clamped(hex_grid(20, 2, 2, cubes(0.05)), 0); }, 1e-2, 3, 5});
    return c;
  }
  // The beams run 100 steps per repetition, as many as their error column: a kept factor is
  // paid once per run, as in a simulation, not once per 20 steps.
  c.push_back({"sofa/8x8x10/h1ms", [] { return clamped(hex_grid(8, 8, 10, cubes(0.0125)), 2); }, 1e-3, 100, 100});
  c.push_back({"tetbeam/5x7x9/h1ms", [] { return clamped(tet_grid(5, 7, 9, TetSplit::kuhn6, cubes(0.01)), 2); }, 1e-3,
               100, 100});
  // The cantilever of bench/results/mss.md: 1 m × 0.1 m × 0.1 m as 10N×N×N cubes, clamped at x = 0.
  c.push_back({"cantilever/N8/h10ms", [] { return clamped(hex_grid(80, 8, 8, cubes(0.1 / 8)), 0); }, 1e-2, 20, 100, 3});
  if (scale == Scale::full) {
    // block-Jacobi CG: ~2-3 s a step (800-1300 iterations) on 46 529 nodes
    c.push_back({"cantilever/N16/h10ms", [] { return clamped(hex_grid(160, 16, 16, cubes(0.1 / 16)), 0); }, 1e-2, 2,
                 10, 1, false, false});
    c.push_back({"scaleup/N16/h0.1ms", [] { return clamped(hex_grid(16, 16, 16, cubes(0.1 / 16)), 2); }, 1e-4, 10, 100,
                 3, false, true});
    c.push_back({"scaleup/N32/h0.01ms", [] { return clamped(hex_grid(32, 32, 32, cubes(0.1 / 32)), 2); }, 1e-5, 4, 10, 3,
                 false, false});
  }
  return c;
}

// One model per case, kept between benchmarks and reset to rest before each run.
struct Kept {
  std::unique_ptr<MssModel<3>> model;
  std::vector<Eigen::Vector3d> x0, v0;
  Eigen::VectorXd reference;  // positions after error_steps, tight direct solve
  double reference_residual = 0;  // its worst relative residual
  std::string error;          // a failed set-up check
};

Kept& kept(const Case& c) {
  static std::map<std::string, Kept> all;
  Kept& k = all[c.name];
  if (!k.model) {
    k.model = c.build();
    for (Index i = 0; i < k.model->nodes().size(); ++i) {
      k.x0.push_back(k.model->nodes().position(i));
      k.v0.push_back(k.model->nodes().velocity(i));
    }
  }
  return k;
}

void restore(Kept& k) {
  for (Index i = 0; i < k.model->nodes().size(); ++i) {
    k.model->nodes().set_position(i, k.x0[i]);
    k.model->nodes().set_velocity(i, k.v0[i]);
  }
}

// floor: the library's absolute floors (a velocity error, a force imbalance; ImplicitEulerOptions)
// or none, the rule.
ImplicitEulerOptions options_for(solve::Backend b, double tolerance, bool floor) {
  ImplicitEulerOptions o;
  o.solver = b;
  o.cg_tolerance = tolerance;
  if (!floor) {
    o.cg_absolute_tolerance = 0.0;
    o.cg_absolute_acceleration = 0.0;
  }
  o.cg_max_iterations = solve::default_max_iterations;
  o.health.energy_check_interval = 0;
  return o;
}

Eigen::VectorXd positions(MssModel<3>& m) { return m.nodes().positions_flat(); }

// Positions after c.error_steps steps with backend b at its default tolerances.
Eigen::VectorXd run_for_error(Kept& k, const Case& c, solve::Backend b, double tolerance, bool floor, bool tight) {
  restore(k);
  ImplicitEulerOptions o = options_for(b, tolerance, floor);
  // 1e-12 is below the round-off floor ε‖A‖‖x‖/‖b‖ of the stiffest cases (the cantilever at
  // h = 10 ms stops near 1e-11): the reference takes what refinement reaches, reported below.
  o.throw_on_cg_failure = !tight;
  LinearlyImplicitEuler ie(o);
  for (int s = 0; s < c.error_steps; ++s) {
    const StepReport r = ie.step(k.model->system(), c.h);
    if (tight) k.reference_residual = std::max(k.reference_residual, r.solve.relative_residual);
  }
  if (tight && !(k.reference_residual < 1e-9))
    throw std::runtime_error(c.name + ": the reference solve reached only " + std::to_string(k.reference_residual));
  Eigen::VectorXd x = positions(*k.model);
  restore(k);
  return x;
}

double error_of(Kept& k, const Case& c, solve::Backend b, bool floor) {
  if (k.reference.size() == 0) {
    // the direct solve with refinement where it runs (CG at 1e-12 may stall at the round-off
    // floor of the stiffest cases and then spends its iteration limit), else block-Jacobi CG
    const bool direct = c.direct && solve::available(solve::Backend::cholmod);
    k.reference = run_for_error(k, c, direct ? solve::Backend::cholmod : solve::Backend::jacobi, 1e-12, false, true);
  }
  Eigen::VectorXd rest(k.reference.size());
  for (std::size_t i = 0; i < k.x0.size(); ++i) rest.segment<3>(3 * Eigen::Index(i)) = k.x0[i];
  const Eigen::VectorXd x = run_for_error(k, c, b, solve::default_tolerance, floor, false);
  return (x - k.reference).norm() / (k.reference - rest).norm();
}

// The reference, "today's block-Jacobi CG" when issue 14 was written: CG to a relative
// 1e-6 with no absolute floor (the floors, 1e-9 m/s and 1e-6 m/s² times h, came later and stop
// the default jacobi earlier on a body moving slowly). Benchmarked as its own row, "jacobi-ref".
constexpr const char* reference_name = "jacobi-ref";

// floor: whether the backend's solves stop at the library's absolute floors; label: the row's name.
void run(benchmark::State& st, const Case& c, solve::Backend b, bool floor, const std::string& label) {
  Kept& k = kept(c);
  if (!k.error.empty()) {
    st.SkipWithError(k.error.c_str());
    return;
  }
  double err = 0;
  const std::string key = c.name + "/" + label;
  static std::map<std::string, double> errors;
  try {
    if (first_time(key)) errors[key] = error_of(k, c, b, floor);
    err = errors[key];
  } catch (const std::exception& e) {
    k.error = e.what();
    st.SkipWithError(k.error.c_str());
    return;
  }
  double iterations = 0, factorizations = 0, analyse = 0, factor = 0, solve_ms = 0, residual = 0;
  std::unique_ptr<LinearlyImplicitEuler> ie;
  int s = 0;
  for (auto _ : st) {
    if (s % c.steps == 0) {
      const Untimed untimed(st);
      restore(k);
      ie = std::make_unique<LinearlyImplicitEuler>(options_for(b, solve::default_tolerance, floor));
    }
    const StepReport r = ie->step(k.model->system(), c.h);
    iterations += r.solve.iterations;
    factorizations += r.solve.factorizations;
    analyse += r.solve.analyse_ms;
    factor += r.solve.factor_ms;
    solve_ms += r.solve.solve_ms;
    residual = std::max(residual, r.solve.relative_residual);
    ++s;
  }
  restore(k);
  using C = benchmark::Counter;
  st.counters["iterations"] = C(iterations, C::kAvgIterations);
  st.counters["factorizations"] = C(factorizations, C::kAvgIterations);
  st.counters["analyse ms"] = C(analyse, C::kAvgIterations);
  st.counters["factor ms"] = C(factor, C::kAvgIterations);
  st.counters["solve ms"] = C(solve_ms, C::kAvgIterations);
  st.counters["worst relative residual"] = residual;
  st.counters["error after " + std::to_string(c.error_steps) + " steps"] = err;
  st.counters["reference residual"] = k.reference_residual;
  st.counters["_nodes"] = static_cast<double>(k.model->nodes().size());
  // 1 on the row of Backend::automatic at the default floor, for the report's goal on the default
  st.counters["_default"] = b == solve::Backend::automatic && floor ? 1.0 : 0.0;
}

// Threads: the same steps at `threads` threads (ours: 2) and at one (peer), wall time (the
// harness's CPU time is the stepping thread's alone). Semi-implicit steps at 0.9 of the
// stable-step bound of the rest state, implicit ones at the case's step.
std::vector<Case> thread_cases(Scale scale) {
  std::vector<Case> c;
  if (scale == Scale::smoke) {
    c.push_back({"threads/N4", [] { return clamped(hex_grid(4, 4, 4, cubes(0.1 / 4)), 2); }, 1e-4, 3, 0});
    return c;
  }
  c.push_back({"threads/N16", [] { return clamped(hex_grid(16, 16, 16, cubes(0.1 / 16)), 2); }, 1e-4, 20, 0});
  if (scale == Scale::full)
    c.push_back({"threads/N32", [] { return clamped(hex_grid(32, 32, 32, cubes(0.1 / 32)), 2); }, 1e-5, 10, 0});
  return c;
}

void run_threads(benchmark::State& st, const Case& c, bool implicit, int threads) {
  Kept& k = kept(c);
  const int before = thread_count();
  set_thread_count(threads);
  restore(k);
  SymplecticEulerOptions so;
  so.enforce_stable_step = false;
  so.health.energy_check_interval = 0;
  const double h = implicit ? c.h : 0.9 * k.model->system().stable_step().h_max;
  double iterations = 0;
  int s = 0;
  std::unique_ptr<LinearlyImplicitEuler> ie;
  std::unique_ptr<SymplecticEuler> se;
  for (auto _ : st) {
    if (s % c.steps == 0) {
      const Untimed untimed(st);
      restore(k);
      ie = std::make_unique<LinearlyImplicitEuler>(options_for(solve::Backend::jacobi, solve::default_tolerance, true));
      se = std::make_unique<SymplecticEuler>(so);
    }
    if (implicit)
      iterations += ie->step(k.model->system(), h).solve.iterations;
    else
      (void)se->step(k.model->system(), h);
    ++s;
  }
  restore(k);
  set_thread_count(before);
  using C = benchmark::Counter;
  st.counters["threads"] = threads;
  if (implicit) st.counters["iterations"] = C(iterations, C::kAvgIterations);
}

void register_all() {
  for (const Case& c : thread_cases(scale()))
    for (const bool implicit : {false, true}) {
      const std::string name = c.name + (implicit ? "/implicit" : "/semi_implicit") + "/2_threads";
      ours(suite, name, [c, implicit](benchmark::State& st) { run_threads(st, c, implicit, 2); })
          ->Iterations(c.steps * (implicit ? 1 : 20))
          ->UseRealTime();
      peer(suite, name, "1 thread", [c, implicit](benchmark::State& st) { run_threads(st, c, implicit, 1); })
          ->Iterations(c.steps * (implicit ? 1 : 20))
          ->UseRealTime();
    }
  // One row: `label` (backend b, at the library's floors or none) against today's jacobi, interleaved.
  const auto add = [](const Case& c, const std::string& label, solve::Backend b, bool row_floor) {
    auto* o = ours(suite, c.name + "/" + label,
                   [c, b, row_floor, label](benchmark::State& st) { run(st, c, b, row_floor, label); })
                  ->Iterations(c.steps);
    auto* p = peer(suite, c.name + "/" + label, "jacobi",
                   [c](benchmark::State& st) { run(st, c, solve::Backend::jacobi, true, "jacobi"); })
                  ->Iterations(c.steps);
    if (c.repetitions > 0) {
      o->Repetitions(c.repetitions);
      p->Repetitions(c.repetitions);
    }
  };
  for (const Case& c : cases(scale())) {
    // the reference (block-Jacobi CG, relative 1e-6, no floor) against today's jacobi
    add(c, reference_name, solve::Backend::jacobi, false);
    add(c, "auto", solve::Backend::automatic, true);  // what the library picks
    for (solve::Backend b : solve::available_backends()) {
      if (b == solve::Backend::jacobi || (b == solve::Backend::cholmod && !c.direct) ||
          (b == solve::Backend::cholmod_pcg && !c.pcg))
        continue;
      const std::string name(solve::to_string(b));
      add(c, name, b, true);
      // The kept-preconditioner backends also by the reference's rule (no floor), so that they
      // can be compared with it at equal error where the floor stops them earlier (the beams);
      // not hypre-pcg and petsc, several times slower than these on every case.
      if (b == solve::Backend::cholmod_pcg || b == solve::Backend::sa_pcg) add(c, name + "-nofloor", b, false);
    }
  }
}

const Registration registration(&register_all);

}  // namespace

}  // namespace sewn::bench::solve_suite
