// bench_elastic, cost per SIMULATED SECOND against error (issue 15's Pareto plot): the static
// rows' models run from release to rest by Newton backward Euler, as bench/mss/cantilever.cpp
// runs the mass-spring beam, so every family's cost is per simulated second:
//   elastic/to_rest/tets/N<n>/h1e<k>               the StVK tet cantilever (tet_cantilever.hpp)
//   elastic/to_rest/shell_strip/patch/square/nx<n>/h1e<k>   the plate strip (shell_strip.hpp)
//   elastic/to_rest/rod/seg<n>/h1e<k>              a rod cantilever under its weight (below)
// Each run starts at rest, undeformed, under gravity, with a drag -c·m·v (MassDamping, through
// its dissipation potential in Newton) of c = 2ω₁, twice the model's first Euler-Bernoulli
// bending frequency: the first mode near critically damped, the drag zero at rest, so the
// equilibrium reached is the static rows' one. Stepped at a fixed h (LDLT, Newton stopping when
// its update is below 1e-6 of the continuum tip deflection) until "at rest", checked after
// every step (every millisecond of simulated time below h = 1 ms) as bench/mss does:
//   ‖F‖ on free axes ≤ 1e-6 ‖m g‖   (net force: elastic + gravity + drag)
//   E_kin ≤ 1e-12 W_g                (W_g = work done by gravity since the release)
// (the strip and the rod replace the force criterion, which rounding floors near or above 1e-6 on
// their stiff membranes and axes, by the kinetic one held for a first-mode period; see below).
// Reported: CPU s per simulated s (thread CPU time of the steps only, the rest checks
// excluded), the tip and its error against the static rows' continuum answer (Timoshenko
// 14.868 mm for the tets, Euler-Bernoulli 0.73575 mm for the strip; Euler-Bernoulli 1.925 mm
// for the rod, which has no static row under gravity), steps, simulated time, Newton
// iterations per step and the worst step's.
#include <time.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <numbers>
#include <string>
#include <vector>

#include "sewn/physics/basic_terms.hpp"
#include "sewn/physics/integrate/newton_euler.hpp"
#include "sewn/physics/rods/rods_term.hpp"
#include "shell_strip.hpp"
#include "tet_cantilever.hpp"
#include "sewn_bench.hpp"

namespace bench_to_rest {
namespace {

namespace physics = sewn::physics;
namespace integrate = sewn::physics::integrate;

constexpr double kinetic_tolerance = 1e-12;  // E_kin / W_g at rest
constexpr double max_simulated_time = 5.0;   // s; a run not at rest by then fails
constexpr double first_root = 1.875104068711961;  // β₁L of the clamped-free beam

double thread_cpu_seconds() {
  timespec t{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &t);
  return static_cast<double>(t.tv_sec) + 1e-9 * static_cast<double>(t.tv_nsec);
}

// ω₁ = (β₁L)² √(EI / (ρA L⁴)): the first mode of the clamped-free Euler-Bernoulli beam.
double first_mode(double EI, double rho_A, double L) {
  return first_root * first_root * std::sqrt(EI / (rho_A * L * L * L * L));
}

// ω₁ of a rectangular section, width w and height t (bending in t).
double first_mode_rectangle(double E, double rho, double L, double w, double t) {
  return first_mode(E * w * t * t * t / 12, rho * w * t, L);
}

struct RunResult {
  std::uint64_t steps = 0;
  double cpu_seconds = 0;
  long newton = 0;
  int worst_newton = 0;
  bool at_rest = false;
  double force_ratio = 0, kinetic_ratio = 0;  // ‖F‖ / ‖m g‖ and E_kin / W_g at the last check
};

// One run: what it is (for errors), its step, gravity, drag, the continuum tip, Newton's
// tolerance on its update, and "at rest": the net-force tolerance ‖F‖ / ‖m g‖ (0: not
// checked) and how long (s of simulated time) the kinetic criterion must have held.
struct Case {
  std::string what;
  double h = 1e-2, g = 9.81, drag = 0, answer_mm = 0, newton_tolerance_m = 0, force_tolerance = 1e-6, hold_s = 0;
};

// Steps sys by c.h from its state until at rest (see the header) or max_simulated_time.
RunResult run_to_rest(physics::System& sys, integrate::NewtonEuler& newton, const Case& c) {
  const double h = c.h, g = c.g;
  physics::NodeTable& nodes = sys.nodes();
  const std::size_t n3 = nodes.x().size();
  const std::vector<double> x0(nodes.x().begin(), nodes.x().end());
  const std::vector<double> inv_mass(nodes.inverse_mass_dof().begin(), nodes.inverse_mass_dof().end());
  const std::vector<double> mass(nodes.masses().begin(), nodes.masses().end());
  double weight2 = 0;  // ‖m g‖² over free nodes
  for (std::size_t k = 2; k < n3; k += 3)
    if (inv_mass[k] != 0.0) weight2 += std::pow(mass[k / 3] * g, 2);
  const auto check_every = std::max<std::uint64_t>(1, static_cast<std::uint64_t>(std::lround(1e-3 / h)));
  RunResult r;
  double still_since = -1;  // simulated time since when the kinetic criterion holds, -1: not now
  while (static_cast<double>(r.steps) * h < max_simulated_time) {
    const double t0 = thread_cpu_seconds();
    const int it = newton.step(sys, h).iterations;
    r.cpu_seconds += thread_cpu_seconds() - t0;
    r.newton += it;
    r.worst_newton = std::max(r.worst_newton, it);
    if (++r.steps % check_every != 0) continue;
    sys.compute_forces();  // at the new state and velocities: drag included
    const auto f = nodes.f();
    const auto v = nodes.v();
    const auto x = nodes.x();
    double force2 = 0, kinetic = 0, work = 0;
    for (std::size_t k = 0; k < n3; ++k) {
      if (inv_mass[k] == 0.0) continue;
      force2 += f[k] * f[k];
      kinetic += 0.5 * mass[k / 3] * v[k] * v[k];
    }
    for (std::size_t k = 2; k < n3; k += 3) work += mass[k / 3] * g * (x0[k] - x[k]);
    r.force_ratio = std::sqrt(force2 / weight2);
    r.kinetic_ratio = kinetic / work;
    const double t = static_cast<double>(r.steps) * h;
    if (r.kinetic_ratio > kinetic_tolerance)
      still_since = -1;
    else if (still_since < 0)
      still_since = t;
    const bool force_ok = c.force_tolerance == 0 || r.force_ratio <= c.force_tolerance;
    if (force_ok && still_since >= 0 && t - still_since >= c.hold_s - 1e-12) {
      r.at_rest = true;
      break;
    }
  }
  return r;
}

// Runs sys to rest and reports the counters; `tip_mm` reads the tip after the run.
template <class Tip>
void report_run(benchmark::State& st, const Case& c, physics::System& sys, Tip tip_mm) {
  sys.add<physics::MassDamping>(c.drag);
  integrate::NewtonEulerOptions opt;
  opt.solver = integrate::LinearSolver::ldlt;
  opt.velocity_tolerance = c.newton_tolerance_m / c.h;
  integrate::NewtonEuler newton(opt);
  RunResult r;
  const std::string& what = c.what;
  const double h = c.h, answer_mm = c.answer_mm;
  try {
    for (auto _ : st) r = run_to_rest(sys, newton, c);
  } catch (const std::exception& e) {
    st.SkipWithError((what + ": " + e.what()).c_str());
    return;
  }
  if (!r.at_rest) {
    st.SkipWithError((what + ": not at rest after " + std::to_string(max_simulated_time) + " s (|F| / |m g| = " +
                      std::to_string(r.force_ratio) + ", E_kin / W_g = " + std::to_string(r.kinetic_ratio) + ")")
                         .c_str());
    return;
  }
  const double simulated = static_cast<double>(r.steps) * h, tip = tip_mm();
  st.counters["CPU s per simulated s"] = r.cpu_seconds / simulated;
  st.counters["tip mm"] = tip;
  st.counters["error %"] = 100.0 * std::abs(tip - answer_mm) / answer_mm;
  st.counters["steps"] = static_cast<double>(r.steps);
  st.counters["simulated s"] = simulated;
  st.counters["Newton iterations per step"] = static_cast<double>(r.newton) / static_cast<double>(r.steps);
  st.counters["worst Newton iterations"] = r.worst_newton;
  st.counters["_answer_mm"] = answer_mm;
  st.counters["_cpu_s_per_simulated_s"] = r.cpu_seconds / simulated;
  st.counters["_h"] = h;
  st.counters["_force_ratio"] = r.force_ratio;
  st.counters["_dof"] = 3.0 * sys.nodes().num_alive();
}

void tets_to_rest(benchmark::State& st, int n, double h) {
  namespace tc = sewn::tet_cantilever;
  tc::Beam beam;
  tc::build(beam, n);
  const Case c{"tets to rest N=" + std::to_string(n), h, tc::g, 2.0 * first_mode_rectangle(tc::E, tc::rho, tc::L, tc::b, tc::b),
               tc::timoshenko_mm, 1e-6 * tc::timoshenko_mm * 1e-3, 1e-6};
  report_run(st, c, beam.sys, [&] { return tc::tip_mm(beam); });
}

void strip_to_rest(benchmark::State& st, int nx, double h) {
  namespace ss = sewn::shell_strip;
  ss::Built strip;
  ss::build(strip, ss::Mesh::square, ss::Bending::patch, nx);
  const double answer_m = ss::euler_bernoulli_m(), omega = first_mode_rectangle(ss::young, ss::rho, ss::length, ss::width, ss::thickness);
  // The net force is not checked: rounding the positions (1e-16 m) of a membrane of stiffness
  // E t = 2e9 N/m leaves ~1e-7 N per element, ‖F‖ / ‖m g‖ ~3e-6 at nx = 40 and 1.2e-5 at
  // nx = 80 (measured), growing with the node count. Instead E_kin ≤ 1e-12 W_g must hold at
  // every check for a whole period 2π/ω₁ of the first mode, so no mode can be at a turning point
  // throughout: that bounds its amplitude as the force criterion would (A/δ ≲ 1e-6).
  const Case c{"shell strip to rest nx=" + std::to_string(nx), h, ss::gravity, 2.0 * omega, 1e3 * answer_m, 1e-6 * answer_m,
               0.0, 2 * std::numbers::pi / omega};
  report_run(st, c, strip.sys, [&] { return 1e3 * ss::tip_m(strip); });
}

// The rod cantilever under its own weight: a steel rod (E = 200 GPa, ν = 0.3, ρ = 7850 kg/m³,
// radius 1 cm), L = 1 m, clamped at x = 0 and loaded by gravity, whose Euler-Bernoulli tip is
// δ = ρ g A L⁴ / (8 E I) = 1.925 mm (δ/L = 2e-3: the large-deflection correction is ~1e-5 of δ).
// A discrete rod's clamp is its first edge (both vertices and its θ held), and its clamped
// section sits at that edge's midpoint (rod_elastica.cpp): vertices at x = (i - 1/2) l,
// l = L / (segments - 1/2), so the section at x = 0 is clamped and the last vertex is the tip at
// x = L. Lumped masses ρ A l per vertex (half at the tip): the midpoint rule on the weight.
// θ is solved quasi-statically (the rod bends in a plane, no twist couples in).
void rod_to_rest(benchmark::State& st, int segments, double h) {
  namespace rods = physics::rods;
  constexpr double E = 200e9, nu = 0.3, rho = 7850.0, radius = 0.01, L = 1.0, g = 9.81;
  const rods::Section section = rods::Section::circular(E, nu, radius);
  const double area = std::numbers::pi * radius * radius, l = L / (segments - 0.5);
  const double answer_mm = 1e3 * rho * g * area * L * L * L * L / (8 * section.EI1);
  physics::System sys;
  std::vector<physics::Index> ids;
  for (int i = 0; i <= segments; ++i)
    ids.push_back(sys.nodes().add(Eigen::Vector3d((i - 0.5) * l, 0, 0), Eigen::Vector3d::Zero(),
                                  rho * area * l * (i == segments ? 0.5 : 1.0)));
  sys.nodes().fix(ids[0]);
  sys.nodes().fix(ids[1]);
  auto& term = sys.add<rods::Rods>();
  (void)term.add_rod(ids, sys.nodes().x(), false, section);
  term.rod(0).fix_theta(0);
  sys.add<physics::Gravity>(Eigen::Vector3d(0, 0, -g));
  // As the strip: the rod's axial stiffness E A / l (5e9 N/m at 80 segments) leaves a rounding
  // floor on the net force (‖F‖ / ‖m g‖ = 9e-7 at rest at 80 segments, measured, growing with
  // them), so E_kin must stay small for a first-mode period instead.
  const double omega = first_mode(section.EI1, rho * area, L);
  const Case c{"rod to rest segments=" + std::to_string(segments), h, g, 2.0 * omega, answer_mm, 1e-6 * answer_mm * 1e-3, 0.0,
               2 * std::numbers::pi / omega};
  const physics::Index tip = ids.back();
  report_run(st, c, sys, [&] { return -1e3 * sys.nodes().position(tip).z(); });
}

std::string step_name(double h) { return "h1e" + std::to_string(static_cast<int>(std::lround(std::log10(h)))); }

// One run each (long and deterministic; its cost is an average over its steps).
void add(const std::string& name, sewn::bench::Body run) {
  sewn::bench::ours("elastic", "to_rest/" + name, std::move(run))->Unit(benchmark::kMillisecond)->Iterations(1)->Repetitions(1);
}

void register_all() {
  using sewn::bench::Scale;
  const Scale scale = sewn::bench::scale();
  std::vector<int> tets = {1}, strips = {10}, rods = {10};
  std::vector<double> steps = {1e-2};
  if (scale != Scale::smoke) {
    tets = {1, 2, 4};
    strips = {10, 20, 40};
    rods = {10, 20, 40};
  }
  if (scale == Scale::full) {
    tets.push_back(8);
    strips.push_back(80);
    rods.push_back(80);
    steps.push_back(1e-3);
  }
  for (double h : steps) {
    for (int n : tets)
      if (h >= 1e-2 || n <= 2) add("tets/N" + std::to_string(n) + "/" + step_name(h), [n, h](benchmark::State& st) { tets_to_rest(st, n, h); });
    for (int nx : strips)
      if (h >= 1e-2 || nx <= 20)
        add("shell_strip/patch/square/nx" + std::to_string(nx) + "/" + step_name(h),
            [nx, h](benchmark::State& st) { strip_to_rest(st, nx, h); });
    for (int n : rods)
      if (h >= 1e-2 || n <= 20)
        add("rod/seg" + std::to_string(n) + "/" + step_name(h), [n, h](benchmark::State& st) { rod_to_rest(st, n, h); });
  }
}

const sewn::bench::Registration reg(&register_all);

}  // namespace
}  // namespace bench_to_rest
