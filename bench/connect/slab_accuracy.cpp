// bench_connect's speed-against-error rows for the 2019 paper's Fig. 18 slab (issue 16).
//
//   connect/accuracy/slab/<mixed|solid>/c<mm>/h<ms>/ours
//       A slab 0.2 × 0.04 × 0.02 m (E = 10 MPa, ν = 0.3, ρ = 1000) clamped at x = 0, sagging
//       under gravity from rest, critically damped for the beam's first mode, backward Euler by
//       Newton (LDLᵀ) with step h for 0.5 s; cells of c mm, 6 tetrahedra each. `solid`: all
//       tetrahedra; `mixed`: the first half tetrahedra, the second half the shell of the same
//       thickness on the mid-surface, joined along the line where they meet by the stiff
//       (`rigid`) curve connection, as in tests/apps/test_connection_slab.cpp. Counters:
//       "relative error" against the all-solid slab's converged sag (its static sag at the
//       finest c of the run, computed once by Newton steps of 100 s), "error vs beam" against
//       Euler–Bernoulli's q L⁴ / (8 EI), "CPU s/simulated s", "c (mm)", "h (ms)",
//       "Newton iterations/step".

#include <cmath>
#include <ctime>
#include <map>
#include <string>
#include <vector>

#include "sewn/apps/fig18_slab_model.hpp"
#include "sewn/physics/basic_terms.hpp"
#include "sewn/physics/integrate/newton_euler.hpp"
#include "sewn_bench.hpp"

namespace sewn::bench::connect_slab_accuracy {

namespace {

constexpr const char* suite = "connect";
constexpr double L = 0.2, W = 0.04, T = 0.02, E = 1e7, nu = 0.3, rho = 1000, g = 9.81, simulated = 0.5;

struct SlabRun {
  double sag = 0, cpu = 0, newton_per_step = 0;
};

// Runs the slab of cells of c (m) — all tetrahedra, or (mixed) its second half the shell — with
// `steps` steps of h from rest, critically damped; or, `quasi_static`, with the velocities
// zeroed before each step (Newton on the static problem) until the sag settles.
SlabRun run_slab(double c, bool mixed, double h, int steps, bool quasi_static) {
  const auto n = static_cast<std::uint32_t>(std::lround(L / c));
  app::Fig18SlabSpec spec;
  spec.solid = mixed ? n / 2 : n;
  spec.shell = mixed ? n - n / 2 : 0;
  spec.ny = static_cast<std::uint32_t>(std::lround(W / c));
  spec.nz = static_cast<std::uint32_t>(std::lround(T / c));
  spec.cell = c;
  spec.young = E;
  spec.poisson = nu;
  spec.density = rho;
  spec.gravity = g;
  spec.connections = mixed;
  spec.rigid = true;
  const app::Fig18SlabModel slab = app::build_fig18_slab_model(spec);
  physics::MssModel<3>& model = *slab.model;
  // critical damping of the Euler–Bernoulli first mode, ω₁ = 1.875² √(EI / (ρA L⁴))
  const double omega1 = 1.8751 * 1.8751 * std::sqrt(E * W * T * T * T / 12 / (rho * W * T * std::pow(L, 4)));
  if (!quasi_static) model.system().add<physics::MassDamping>(2 * omega1);
  physics::integrate::NewtonEulerOptions no;
  no.max_iterations = 200;
  no.velocity_tolerance = quasi_static ? 1e-12 : 1e-8;
  no.solver = physics::integrate::LinearSolver::ldlt;
  physics::integrate::NewtonEuler newton(no);
  SlabRun out;
  int iterations = 0, taken = 0;
  const std::clock_t c0 = std::clock();
  for (double last = 0; taken < steps; ++taken) {
    if (quasi_static)
      for (double& v : model.nodes().v()) v = 0;
    iterations += newton.step(model.system(), h).iterations;
    // quasi-static: until the sag stops changing (to 1e-12 m)
    if (quasi_static && std::abs(slab.sag() - last) < 1e-12) {
      ++taken;
      break;
    }
    last = slab.sag();
  }
  out.cpu = static_cast<double>(std::clock() - c0) / CLOCKS_PER_SEC;
  out.sag = slab.sag();
  out.newton_per_step = static_cast<double>(iterations) / taken;
  return out;
}

// The all-solid slab's static sag at cell size c, computed once per process.
double solid_reference(double c) {
  static std::map<double, double> cache;
  auto it = cache.find(c);
  if (it == cache.end()) it = cache.emplace(c, run_slab(c, false, 100.0, 30, true).sag).first;
  return it->second;
}

void slab_row(benchmark::State& st, double c, double h, bool mixed, double finest) {
  const double reference = solid_reference(finest);
  const double beam = rho * g * W * T * std::pow(L, 4) / (8 * E * W * T * T * T / 12);
  const int steps = static_cast<int>(std::lround(simulated / h));
  SlabRun r;
  double cpu = 0;
  for (auto _ : st) {
    r = run_slab(c, mixed, h, steps, false);
    cpu += r.cpu;
  }
  st.counters["relative error"] = std::abs(r.sag - reference) / reference;
  st.counters["error vs beam"] = std::abs(r.sag - beam) / beam;
  st.counters["sag (mm)"] = r.sag * 1e3;
  st.counters["reference sag (mm)"] = reference * 1e3;
  st.counters["CPU s/simulated s"] = cpu / static_cast<double>(st.iterations()) / simulated;
  st.counters["c (mm)"] = c * 1e3;
  st.counters["h (ms)"] = h * 1e3;
  st.counters["Newton iterations/step"] = r.newton_per_step;
}

void register_all() {
  const Scale sc = scale();
  if (sc == Scale::smoke) return;  // seconds per row: the rod rows prove the plumbing in CI
  const std::vector<double> cells = sc == Scale::small ? std::vector<double>{0.01} : std::vector<double>{0.01, 0.005};
  const double finest = cells.back();
  for (const bool mixed : {true, false})
    for (const double c : cells)
      for (const double h : {0.01, 0.05}) {
        const std::string name = std::string("accuracy/slab/") + (mixed ? "mixed" : "solid") + "/c" +
                                 std::to_string(static_cast<int>(std::lround(c * 1e3))) + "/h" +
                                 std::to_string(static_cast<int>(std::lround(h * 1e3)));
        ours(suite, name, [c, h, mixed, finest](benchmark::State& st) { slab_row(st, c, h, mixed, finest); })
            ->Iterations(1)
            ->Unit(benchmark::kMillisecond);
      }
}

const Registration reg(&register_all);

}  // namespace

}  // namespace sewn::bench::connect_slab_accuracy
