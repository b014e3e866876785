// bench_refine (issue 13): the 2014 paper's Table 1. Cases (one with a CGAL peer):
//   refine/table1/<config>/implicit   ms per step of the beam of Table 1 (two 1 m hexahedra side
//       by side, 2 m x 1 m x 1 m, E = 100 kPa, nu = 0.3, rho = 100, g = 9.81, per-spring viscous
//       damping, clamped at x = 0), linearly implicit Euler, h = 1 ms, CG to 1e-6 (block-Jacobi,
//       the solver layer's best backend here); an adaptive configuration's step includes its
//       criterion pass (adapt(): any refinement it makes is timed too). Counters: live elements
//       per level index ("lvl<k> elements"), T-junctions, particles.
//   refine/table1/<config>/semi       the same state stepped by the semi-implicit (symplectic)
//       Euler at 0.9x the system's stable-step bound, with the criterion pass.
//   refine/subdivision/hex            one hexahedron of the settled adaptive 2-4 beam refined 1:8,
//       T-junction constraints rebuilt (coarsened back, untimed, between repetitions).
//   refine/subdivision/all/<beam>     every hexahedron of the beam refined 1:8 (refine_all, with the
//       physics), against the same subdivision with CGAL LCC's insertions (cgal_subdivide.cpp).
//   refine/subdivision/map/<beam>     the map part alone: CGAL's three passes with our map's own
//       insertions, points only (map_subdivide.cpp), against the same CGAL peer.
//   refine/t_junctions/forces         the T-junction force distribution of one step on the
//       adaptive 2-4 state (SlaveNodes::pass_forces: forces of slaves passed to their masters).
//   The implicit cases also carry "top-edge error (mm)": after 10 000 implicit steps from rest
//   (the paper's Fig. 11), the largest distance between the configuration's top-edge particles
//   and the finest configuration's (refined x4; x3 at the small scale, with 2 000 steps),
//   "mean-shape error (mm)": the same between the top edges averaged over the last 1000 steps
//   (the beams still swing), and "continuum error (mm)": the largest difference between the mean
//   top edge's vertical displacement and Timoshenko's cantilever deflection at the paper's E, nu,
//   rho (the tip's: "tip sag (mm)").
// Configurations (level index 1 + log2 l, the paper's "lvl."): coarse (2 hexahedra of level 1),
// refined x3 (1024 of level 4) and x4 (8192 of level 5), built directly as grids (refining
// uniformly gives the same model, tests/refine), and adaptive 2-3 / 2-4: the coarse beam refined
// once (16 of level 2), then run 1000 steps (1 s) adapting after each (diagonal strain above
// 1.2 %, the paper's threshold, at most one level per step, up to level 3 or 4). The Pareto
// sweep beside them: adaptive 2-4 at a 3 % threshold, adaptive 2-4 of the clamped half (a region,
// x < 1 m, whatever its strain) and refined x2 (bench/refine/notes.md).
#include <cmath>
#include <algorithm>
#include <map>
#include <stdexcept>
#include <memory>
#include <string>
#include <vector>

#include "sewn/physics/integrators.hpp"
#include "sewn/physics/mss_model.hpp"
#include "sewn/refine/coarsen.hpp"
#include "sewn/refine/criteria.hpp"
#include "sewn/refine/criterion.hpp"
#include "sewn/refine/hierarchy.hpp"
#include "sewn/refine/subdivide.hpp"
#include "mss_setup.hpp"
#include "sewn_bench.hpp"
#include "subdivision_cases.hpp"

namespace sewn::bench::refine_suite {
namespace {

using physics::Index;
using physics::MssModel;
using Vec3d = Eigen::Vector3d;

constexpr double kE = 1e5, kNu = 0.3, kRho = 100, kG = -9.81, kH = 1e-3, kThreshold = 1.2;
constexpr int kSettleSteps = 1000, kRestoreEvery = 50;
constexpr int kAccuracySteps = 10000;  // the paper's Fig. 11: positions after 10 000 steps
constexpr const char* kSuite = "refine";

struct Config {
  std::string name;
  int uniform = 0;      // refined x uniform, built directly (adaptive: 0)
  int max_level = 0;    // adaptive: the finest level index (0: not adaptive)
  double threshold = kThreshold;  // adaptive: the diagonal strain threshold, percent
  double region_x = 0;  // adaptive: if > 0, refine the elements whose rest centroid has x below it instead
};

// The criterion of an adaptive configuration: the paper's diagonal strain, or a user region.
std::unique_ptr<refine::Criterion<3>> criterion(const Config& c) {
  if (c.region_x > 0) return std::make_unique<refine::InRegion<3>>([x = c.region_x](const Vec3d& p) { return p.x() < x; });
  return std::make_unique<refine::DiagonalStrain<3>>(c.threshold);
}

std::unique_ptr<MssModel<3>> beam(int refined) {
  auto m = viscous_model(beam_mesh(refined), kE, kNu, kRho, kG, "table1 beam");
  for (Index i = 0; i < m->nodes().size(); ++i)
    if (m->rest_position(i).x() == 0) m->nodes().fix(i);
  return m;
}

physics::ImplicitEulerOptions implicit_options() {
  physics::ImplicitEulerOptions o;
  o.solver = physics::solve::Backend::jacobi;
  o.cg_tolerance = 1e-6;
  return o;
}

// The configuration's model in its measured state: uniform grids at rest, adaptive beams after
// their settling run.
std::unique_ptr<MssModel<3>> build(const Config& c) {
  if (c.max_level == 0) return beam(c.uniform);
  auto m = beam(0);
  refine::RefineOptions ro;
  ro.max_level = c.max_level;
  (void)refine::refine_all(*m, ro);
  const auto wants = criterion(c);
  physics::LinearlyImplicitEuler euler(implicit_options());
  for (int s = 0; s < kSettleSteps; ++s) {
    (void)euler.step(m->system(), kH);
    (void)refine::adapt(*m, *wants, ro);
  }
  return m;
}

// Live elements per level index (a grid built directly at refined x k has level k + 1, as if
// refined k times from the coarse beam), T-junctions, particles.
// The top edge's particles (rest y = 0, z = 1: the paper's "upper particles" seen from the side),
// rest x -> position, after kAccuracySteps implicit steps from rest (adaptive beams adapting
// after each step, from the coarse beam refined once): at the last step (the paper's measure),
// and averaged over the last kSwingSteps. The finer beams still swing at 10 s (refined x4 by
// +-90 mm about its mean, with a period of about 1.05 s: the per-spring damping and the implicit
// step's barely touch the bending mode), so the last step's shape holds the swing's phase; the
// mean over about one period is the sagged shape (docs/refinement.md, "Accuracy against cost").
struct TopEdge {
  std::map<double, Vec3d> last, mean;
};
constexpr int kSwingSteps = 1000;
TopEdge top_edge_after_run(const Config& c) {
  auto m = beam(c.uniform);
  refine::RefineOptions ro;
  ro.max_level = c.max_level;
  if (c.max_level > 0) (void)refine::refine_all(*m, ro);
  const auto wants = criterion(c);
  physics::LinearlyImplicitEuler euler(implicit_options());
  const int n = scale() == Scale::full ? kAccuracySteps : kAccuracySteps / 5;
  const int window = std::min(n, kSwingSteps);
  std::map<double, std::pair<Vec3d, int>> sum;  // a particle refinement adds late counts from then
  TopEdge edge;
  for (int s = 0; s < n; ++s) {
    (void)euler.step(m->system(), kH);
    if (c.max_level > 0) (void)refine::adapt(*m, *wants, ro);
    if (s < n - window) continue;
    for (Index i = 0; i < m->nodes().size(); ++i)
      if (m->nodes().is_alive(i) && m->rest_position(i).y() == 0 && m->rest_position(i).z() == 1) {
        auto& [p, k] = sum.try_emplace(m->rest_position(i).x(), Vec3d::Zero(), 0).first->second;
        p += m->nodes().position(i);
        ++k;
        if (s == n - 1) edge.last[m->rest_position(i).x()] = m->nodes().position(i);
      }
  }
  for (const auto& [x, pk] : sum)
    if (edge.last.count(x)) edge.mean[x] = pk.first / pk.second;
  return edge;
}

// The finest configuration of the scale: the reference of the accuracy rows.
Config finest() { return scale() == Scale::full ? Config{"refined x4", 4, 0} : Config{"refined x3", 3, 0}; }

// The top edge after the accuracy run, once per configuration and process.
const TopEdge& top_edge(const Config& c) {
  static std::map<std::string, TopEdge> cache;
  auto it = cache.find(c.name);
  if (it == cache.end()) it = cache.emplace(c.name, top_edge_after_run(c)).first;
  return it->second;
}

// Largest distance, in mm, between a configuration's top-edge particles and the reference's at
// the same rest place (every rest place of a coarser beam is one of the finest grid's).
double top_edge_error_mm(const Config& c, std::map<double, Vec3d> TopEdge::*shape) {
  const std::map<double, Vec3d>& reference = top_edge(finest()).*shape;
  double worst = 0;
  for (const auto& [x, p] : top_edge(c).*shape) {
    const auto r = reference.find(x);
    if (r == reference.end()) throw std::logic_error("bench refine: rest x = " + std::to_string(x) + " is not a particle of the reference");
    worst = std::max(worst, (p - r->second).norm());
  }
  return worst * 1e3;
}

// The continuum answer: Timoshenko's cantilever of length L under its own weight q = rho g A,
// clamped at x = 0 (deflection and section rotation zero there), linear elastic at the paper's
// E and nu, with Cowper's shear coefficient for a rectangle, kappa = 10(1 + nu)/(12 + 11 nu):
//   w(x) = q/(24 EI) (x^4 - 4 L x^3 + 6 L^2 x^2) + q/(kappa G A) (L x - x^2 / 2),
// bending (Euler-Bernoulli) plus shear. The beam is 2 m x 1 m x 1 m, so A = 1 m^2, I = 1/12 m^4.
double timoshenko_deflection(double x) {
  constexpr double L = 2, A = 1, I = 1.0 / 12, q = kRho * -kG * A;
  constexpr double G = kE / (2 * (1 + kNu)), kappa = 10 * (1 + kNu) / (12 + 11 * kNu);
  return q / (24 * kE * I) * (x * x * x * x - 4 * L * x * x * x + 6 * L * L * x * x) + q / (kappa * G * A) * (L * x - x * x / 2);
}

// Largest difference, in mm, between the top edge's vertical displacement (rest z = 1) and the
// continuum deflection at the same x, on the mean shape of the last swing.
double continuum_error_mm(const Config& c) {
  double worst = 0;
  for (const auto& [x, p] : top_edge(c).mean) worst = std::max(worst, std::abs(p.z() - 1 + timoshenko_deflection(x)));
  return worst * 1e3;
}

void count(benchmark::State& st, const MssModel<3>& m, int uniform = 0) {
  std::map<int, int> per_level;
  for (const auto& e : m.elements())
    if (e.alive) ++per_level[refine::level_index(e.level) + uniform];
  for (const auto& [level, n] : per_level) st.counters["lvl" + std::to_string(level) + " elements"] = n;
  st.counters["T-junctions"] = static_cast<double>(m.system().slaves().slaves().size());
  st.counters["particles"] = m.nodes().num_alive();
}

struct Saved {
  std::vector<double> x, v;
};
Saved save(const MssModel<3>& m) {
  const auto& n = m.nodes();
  Saved s;
  s.x.assign(n.positions().data(), n.positions().data() + 3 * n.size());
  s.v.assign(n.velocities().data(), n.velocities().data() + 3 * n.size());
  return s;
}
void restore(MssModel<3>& m, const Saved& s) {
  auto& n = m.nodes();
  std::copy(s.x.begin(), s.x.end(), n.positions().data());
  std::copy(s.v.begin(), s.v.end(), n.velocities().data());
}

// A configuration's model in its measured state, built once per process (an adaptive state
// takes seconds to settle) and restored to that state at every reuse; rebuilt if a criterion
// pass refined it since.
struct Built {
  std::unique_ptr<MssModel<3>> m;
  Saved start;
  Index elements = 0;
};
MssModel<3>& cached(const Config& c) {
  static std::map<std::string, Built> cache;
  Built& b = cache[c.name];
  if (!b.m || b.m->num_live_elements() != b.elements) {
    b.m = build(c);
    b.start = save(*b.m);
    b.elements = b.m->num_live_elements();
  } else {
    restore(*b.m, b.start);
  }
  return *b.m;
}

// Steps of one configuration; the state is restored (untimed) every kRestoreEvery steps so that
// the measured state stays the configuration's (and so does its element count). Resetting the
// semi-implicit integrator there would make it take its stable-step bound every 50 steps, a
// quarter to a third of every semi-implicit row's time, where a run takes it every 100.
void steps(benchmark::State& st, const Config& c, bool implicit) {
  MssModel<3>* m = &cached(c);  // set-up before the timed loop is not timed
  refine::RefineOptions ro;
  ro.max_level = c.max_level;
  const auto wants = criterion(c);
  physics::LinearlyImplicitEuler euler(implicit_options());
  physics::SymplecticEuler semi;
  const double h = implicit ? kH : 0.9 * m->system().stable_step().h_max;
  const Index settled = m->num_live_elements();
  int since = 0;
  for (auto _ : st) {
    if (implicit)
      (void)euler.step(m->system(), h);
    else
      (void)semi.step(m->system(), h);
    if (c.max_level > 0) (void)refine::adapt(*m, *wants, ro);
    if (++since == kRestoreEvery) {
      Untimed pause(st);
      // the implicit step starts its CG guess afresh; the semi-implicit one keeps its bound, the
      // restored state's own, and rechecks it at its interval (100 steps) as any run does, unless
      // a refinement made cached() build the model anew
      if (m->num_live_elements() != settled) semi.reset();
      euler.reset();
      m = &cached(c);
      since = 0;
    }
  }
  count(st, *m, c.uniform);
  st.counters["h (ms)"] = h * 1e3;
  if (implicit && scale() != Scale::smoke) {
    st.counters["top-edge error (mm)"] = top_edge_error_mm(c, &TopEdge::last);
    st.counters["mean-shape error (mm)"] = top_edge_error_mm(c, &TopEdge::mean);
    st.counters["continuum error (mm)"] = continuum_error_mm(c);
    st.counters["tip sag (mm)"] = (1 - top_edge(c).mean.rbegin()->second.z()) * 1e3;
  }
}

// One hexahedron of the settled adaptive 2-4 beam refined 1:8 (the first live one below level
// 4), then coarsened back untimed: refine-then-coarsen gives back the model (tests/refine).
void subdivision(benchmark::State& st) {
  std::unique_ptr<MssModel<3>> m = build({"adaptive 2-4", 0, 4});
  Index pick = physics::invalid_index;
  for (Index e = 0; e < m->elements().size() && pick == physics::invalid_index; ++e)
    if (m->elements()[e].alive && refine::level_index(m->elements()[e].level) < 4) pick = e;
  if (pick == physics::invalid_index) {
    st.SkipWithError("no hexahedron below level 4 in the adaptive 2-4 beam");
    return;
  }
  for (auto _ : st) {
    benchmark::DoNotOptimize(refine::refine_element(*m, pick, {}));
    Untimed pause(st);
    (void)refine::coarsen(*m, pick);
  }
  count(st, *m);
}

// Every hexahedron of a beam refined 1:8 by refine_all (particles, masses, springs and hierarchy
// included), on a beam built afresh with the clock paused; the CGAL-LCC peer subdivides the same
// beam's map (cgal_subdivide.cpp).
void subdivide_all(benchmark::State& st, const SubdivisionCase& c) {
  std::unique_ptr<MssModel<3>> m;
  for (auto _ : st) {
    {
      Untimed pause(st);
      m.reset();
      m = beam(c.refined);
    }
    benchmark::DoNotOptimize(refine::refine_all(*m, {}));
  }
  st.counters["hexahedra"] = static_cast<double>(m->num_live_elements());
  if (first_time("subdivision/ours/" + c.name)) {
    const Index want = Index{16} << (3 * c.refined);
    const auto map_report = m->map().validate();
    const refine::HierarchyReport hierarchy = refine::check_hierarchy(*m);
    if (m->num_live_elements() != want)
      st.SkipWithError(("refine_all left " + std::to_string(m->num_live_elements()) + " hexahedra, expected " + std::to_string(want)).c_str());
    else if (!map_report.ok())
      st.SkipWithError(("refine_all: " + map_report.str(3)).c_str());
    else if (!hierarchy.ok())
      st.SkipWithError(("refine_all: " + hierarchy.str()).c_str());
  }
}

void t_junction_forces(benchmark::State& st) {
  MssModel<3>* m = &cached({"adaptive 2-4", 0, 4});
  m->system().compute_forces();
  const auto& n = m->nodes();
  std::vector<double> f(n.forces().data(), n.forces().data() + 3 * n.size());
  for (auto _ : st) {
    m->system().slaves().pass_forces(f);
    benchmark::DoNotOptimize(f.data());
  }
  count(st, *m);
}

void register_all() {
  std::vector<Config> configs{{"coarse", 0, 0}, {"adaptive 2-3", 0, 3}, {"refined x3", 3, 0}};
  if (scale() != Scale::smoke) {
    configs.push_back({"adaptive 2-4", 0, 4});
    // the Pareto sweep beside the paper's configurations (bench/refine/notes.md): a laxer
    // threshold, and the clamped half refined whatever its strain
    configs.push_back({"adaptive 2-4 at 3 %", 0, 4, 3.0});
    configs.push_back({"adaptive 2-4 clamped half", 0, 4, kThreshold, 1.0});
    configs.push_back({"refined x2", 2, 0});  // the uniform grid the sweep's cheap points compete with
  }
  if (scale() == Scale::full) configs.push_back({"refined x4", 4, 0});
  for (const Config& c : configs)
    for (bool implicit : {true, false})
      ours(kSuite, "table1/" + c.name + (implicit ? "/implicit" : "/semi"), [c, implicit](benchmark::State& st) { steps(st, c, implicit); });
  if (scale() != Scale::smoke) {
    ours(kSuite, "subdivision/hex", subdivision);
    ours(kSuite, "t_junctions/forces", t_junction_forces);
  }
  for (const SubdivisionCase& c : subdivision_cases())
    ours(kSuite, "subdivision/" + c.name, [c](benchmark::State& st) { subdivide_all(st, c); });
}

const Registration reg(&register_all);

}  // namespace
}  // namespace sewn::bench::refine_suite
