// bench_connect's speed-against-error rows (issue 16): what a connected model costs per
// simulated second for the accuracy it reaches.
//
//   connect/accuracy/rod/<split|unsplit>/n<N>/h<ms>/ours
//       A steel cantilever (L = 0.5 m, r = 5 mm) of N free rod edges (plus one held edge across
//       x = 0, which clamps it at x = 0) sagging under gravity from rest, critically damped for its first mode, backward
//       Euler by Newton with step h for 0.2 s of simulated time; `split`: cut in two at its
//       middle node and joined there by a point connection with k_t = GJ/D, k_b = EI/D (D the
//       edge length). Counters: "relative error" of the tip deflection against the
//       Euler–Bernoulli answer q L⁴ / (8 EI) (the tip is then 1e-3 of L, so the geometric
//       nonlinearity is ~1e-6 of it), "CPU s/simulated s", "N", "h (ms)",
//       "Newton iterations/step".
//
// The transient has decayed by e^-35 at 0.2 s (every mode decays at least at the first mode's
// rate), so what is left is the discretisation's error (and Newton's tolerance, 1e-8 m/s).

#include <cmath>
#include <ctime>
#include <numbers>
#include <string>
#include <vector>

#include "sewn/connect/point_term.hpp"
#include "sewn/physics/basic_terms.hpp"
#include "sewn/physics/integrate/newton_euler.hpp"
#include "sewn/physics/rods/rods_term.hpp"
#include "sewn/physics/system.hpp"
#include "sewn_bench.hpp"

namespace sewn::bench::connect_accuracy {

namespace {

constexpr const char* suite = "connect";
constexpr double pi = std::numbers::pi;
constexpr double L = 0.5, radius = 0.005, E = 2e11, nu = 0.3, rho = 7800, g = 9.81, T = 0.2;

struct RodRun {
  double tip = 0;          // m, downward deflection at x = L
  double cpu = 0;          // s, the steps' process CPU time
  double newton_steps = 0;  // Newton iterations per step
};

// The cantilever of n free edges from x = 0 to L, run for T seconds. Holding the first edge's
// two nodes clamps the rod where that edge's bending stencil (the Voronoi interval of its
// second node, of length D) begins: so node 0 sits at −D/2, node 1 at D/2 (both held, with θ of
// their edge), and the free nodes follow at D, D = L / (n + ½), the tip at L. Split, the rod is
// cut at its middle node 1 + n/2 (n even) into two rods joined by a point connection.
RodRun run_rod(std::uint32_t n, double h, bool split) {
  physics::System sys;
  const auto sec = physics::rods::Section::circular(E, nu, radius);
  const double D = L / (n + 0.5);
  std::vector<physics::Index> ids;
  for (std::uint32_t i = 0; i <= n + 1; ++i) {
    const double mass = rho * pi * radius * radius * D * (i == n + 1 ? 0.5 : 1.0);
    ids.push_back(sys.nodes().add(Eigen::Vector3d((static_cast<double>(i) - 0.5) * D, 0, 0), Eigen::Vector3d::Zero(), mass));
  }
  sys.nodes().fix(ids[0]);
  sys.nodes().fix(ids[1]);
  auto& rods = sys.add<physics::rods::Rods>();
  const std::uint32_t mid = 1 + n / 2;
  if (split) {
    (void)rods.add_rod(std::vector<physics::Index>(ids.begin(), ids.begin() + mid + 1), sys.nodes().x(), false, sec);
    (void)rods.add_rod(std::vector<physics::Index>(ids.begin() + mid, ids.end()), sys.nodes().x(), false, sec);
  } else {
    (void)rods.add_rod(ids, sys.nodes().x(), false, sec);
  }
  rods.rod(0).fix_theta(0);
  rods.use_angle_dofs(sys.angles(), rho * pi * std::pow(radius, 4) / 2);
  if (split) {
    auto& joint = sys.add<connect::PointConnections>(&rods);
    (void)joint.add("joint", connect::RodEdgeRef{0, static_cast<int>(mid - 1)}, connect::RodEdgeRef{1, 0},
                    {sec.GJ / D, sec.EI1 / D}, sys.state());
  }
  sys.add<physics::Gravity>(Eigen::Vector3d(0, 0, -g));
  // critical damping of the first mode, ω₁ = 1.875² √(EI / (ρA L⁴))
  const double omega1 = 1.8751 * 1.8751 * std::sqrt(sec.EI1 / (rho * pi * radius * radius * std::pow(L, 4)));
  sys.add<physics::MassDamping>(2 * omega1);
  physics::integrate::NewtonEulerOptions no;
  no.velocity_tolerance = 1e-8;
  no.max_iterations = 100;
  no.solver = physics::integrate::LinearSolver::ldlt;
  physics::integrate::NewtonEuler newton(no);
  const auto steps = static_cast<int>(std::lround(T / h));
  RodRun out;
  const std::clock_t c0 = std::clock();
  int iterations = 0;
  for (int s = 0; s < steps; ++s) iterations += newton.step(sys, h).iterations;
  out.cpu = static_cast<double>(std::clock() - c0) / CLOCKS_PER_SEC;
  out.tip = -sys.nodes().position(ids.back()).z();
  out.newton_steps = static_cast<double>(iterations) / steps;
  return out;
}

void rod_row(benchmark::State& st, std::uint32_t n, double h, bool split) {
  const auto sec = physics::rods::Section::circular(E, nu, radius);
  const double q = rho * pi * radius * radius * g, exact = q * std::pow(L, 4) / (8 * sec.EI1);
  RodRun r;
  double cpu = 0;
  for (auto _ : st) {
    r = run_rod(n, h, split);
    cpu += r.cpu;
  }
  st.counters["relative error"] = std::abs(r.tip - exact) / exact;
  st.counters["CPU s/simulated s"] = cpu / static_cast<double>(st.iterations()) / T;
  st.counters["N"] = n;
  st.counters["h (ms)"] = h * 1e3;
  st.counters["Newton iterations/step"] = r.newton_steps;
}

void register_all() {
  const Scale sc = scale();
  const std::vector<std::uint32_t> ns = sc == Scale::smoke ? std::vector<std::uint32_t>{8}
                                        : sc == Scale::small ? std::vector<std::uint32_t>{8, 16}
                                                             : std::vector<std::uint32_t>{8, 16, 32, 64};
  const std::vector<double> hs = sc == Scale::smoke ? std::vector<double>{0.01} : std::vector<double>{0.002, 0.01};
  for (const bool split : {true, false})
    for (const std::uint32_t n : ns)
      for (const double h : hs) {
        const std::string c = std::string("accuracy/rod/") + (split ? "split" : "unsplit") + "/n" + std::to_string(n) + "/h" +
                              std::to_string(static_cast<int>(std::lround(h * 1e3)));
        ours(suite, c, [n, h, split](benchmark::State& st) { rod_row(st, n, h, split); })->Iterations(1)->Unit(benchmark::kMillisecond);
      }
}

const Registration reg(&register_all);

}  // namespace

}  // namespace sewn::bench::connect_accuracy
