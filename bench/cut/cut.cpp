// The cut suite (issue 4): what one cut costs next to one simulation step on the same mesh.
//
// "ours" is one call to refine::cut(model, facets): the 3-unsew of the faces and the physics
// update MssModel::edit() does (particles and springs duplicated, masses, stiffnesses and
// diagonal attachments recomputed). The facets are selected before timing, on a model built
// the same way (the build is deterministic, so its darts name the same faces), and every
// repetition cuts a freshly built model, rebuilt with the clock paused: a cut cannot be undone,
// and MssModel cannot be copied. Faces: 1 (the face of a middle plane nearest the plane's
// centre), 10 (the 10 nearest) and all faces of that plane.
//
// The peers are steps of the same model, with the 2013 paper's material (E = 100 MPa, ν = 0.3,
// ρ = 1000, g = 9.8, per-spring viscosity), one face clamped, default health checks:
//   "1 semi-implicit step"   physics::SymplecticEuler, enforce_stable_step = false, at half the
//                            model's stable-step bound (the paper's 1 ms is far above the explicit
//                            limit of these meshes, PHYSICS_NOTES §1.6, and the energy watchdog
//                            stops such a run within 100 steps; the cost of a step does not
//                            depend on h);
//   "5 semi-implicit steps"  the same, 5 in a row (the goal for a whole plane of the 32³ beam);
//   "1 implicit step"        physics::LinearlyImplicitEuler (CG to 1e-6), h = 1 ms, as the paper
//                            cuts; the state is restored (untimed) every 50 steps.
//
// refine::cut leaves part of the update to the next step: the System rebuilds its Jacobian
// block pattern when it sees the topology changed (System::refresh), for either integrator, and
// the energy watchdog takes a new baseline. The cases first_step_after_* time that first
// semi-implicit step after a cut (the cut untimed) against an ordinary step, so that the cut's
// whole cost is cut + (first step after - step). stable_step_bound times the bound a guarded run
// (the default) recomputes after every cut: the rest of what a cut costs such a run.
//
// Meshes: the 8x8x10 grid of 1.25 cm cubes (the paper's SOFA comparison, 891 particles), the 32³
// grid of 0.3125 cm cubes (the paper's largest scale-up beam, 35 937 particles), and a stand-in
// for the paper's frog with its counts (26 125 hexahedra, 32 934 particles, see frog.cpp).
#include <algorithm>
#include <cmath>
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

#include "frog.hpp"
#include "sewn/cmap/mesh.hpp"
#include "sewn/physics/integrators.hpp"
#include "sewn/physics/mss_model.hpp"
#include "sewn/refine/cut.hpp"
#include "mss_setup.hpp"
#include "sewn_bench.hpp"

namespace sewn::bench::cut {
namespace {

using physics::MssModel;
using Vec3d = Eigen::Vector3d;

constexpr double kE = 1e8, kNu = 0.3, kRho = 1000, kG = -9.8, kH = 1e-3;
constexpr int kImplicitReset = 50;  // implicit steps before the state is restored
constexpr const char* kSuite = "cut";

struct MeshCase {
  std::string name;
  IndexedMesh mesh;
  Vec3d plane_point, plane_normal;  // the middle plane, through the centre of its section
  int clamp_axis;                   // particles at the minimum of this rest coordinate are fixed
  int rebuild_iterations;           // cuts per repetition (each on a freshly built model)
};

std::unique_ptr<MssModel<3>> build_model(const MeshCase& c) {
  auto m = viscous_model(c.mesh, kE, kNu, kRho, kG, c.name);
  double lo = INFINITY;
  for (physics::Index i = 0; i < m->nodes().size(); ++i) lo = std::min(lo, m->rest_position(i)[c.clamp_axis]);
  for (physics::Index i = 0; i < m->nodes().size(); ++i)
    if (m->rest_position(i)[c.clamp_axis] <= lo) m->nodes().fix(i, physics::axis_x | physics::axis_y | physics::axis_z);
  return m;
}

// Half the model's stable semi-implicit step bound: a step that a real run could take.
double semi_implicit_h(MssModel<3>& m) { return 0.5 * m.system().stable_step().h_max; }

// The cut selections of one mesh, made once on a built model.
struct Selections {
  std::vector<refine::Facet> one, ten, plane;
};

Selections select(const MeshCase& c) {
  const auto m = build_model(c);
  Selections s;
  s.plane = refine::facets_across_plane(*m, c.plane_point, c.plane_normal);
  if (s.plane.size() < 10) throw std::logic_error("bench_cut: " + c.name + ": the middle plane has fewer than 10 faces");
  // the faces nearest the plane's centre: one face, then a compact patch of ten
  auto centroid = [&](const refine::Facet& f) {
    Vec3d p = Vec3d::Zero();
    int n = 0;
    Dart x = f.dart;
    do {
      p += m->rest_position(m->node_of(x));
      ++n;
      x = m->map().beta(x, 1);
    } while (x != f.dart);
    return Vec3d(p / n);
  };
  std::vector<std::pair<double, std::size_t>> by_distance;
  for (std::size_t k = 0; k < s.plane.size(); ++k) by_distance.emplace_back((centroid(s.plane[k]) - c.plane_point).norm(), k);
  std::sort(by_distance.begin(), by_distance.end());
  for (std::size_t k = 0; k < 10; ++k) {
    if (k == 0) s.one.push_back(s.plane[by_distance[k].second]);
    s.ten.push_back(s.plane[by_distance[k].second]);
  }
  return s;
}

// Once per case: the cut unsews every selected face of a fresh model, the model stays sound and
// the step after it runs; so a timing never comes from a cut that did nothing.
void check_cut(const MeshCase& c, const std::vector<refine::Facet>& facets, const std::string& what) {
  if (!first_time(c.name + "/" + what)) return;
  auto m = build_model(c);
  const double mass = m->node_mass();
  const refine::CutReport r = refine::cut(*m, facets);
  if (r.facets != facets.size())
    throw std::logic_error("bench_cut: " + c.name + "/" + what + ": unsewed " + std::to_string(r.facets) + " of " +
                           std::to_string(facets.size()) + " faces");
  if (const auto v = m->map().validate(); !v.ok()) throw std::logic_error("bench_cut: " + c.name + ": invalid map after the cut");
  if (std::abs(m->node_mass() - mass) > 1e-9 * mass) throw std::logic_error("bench_cut: " + c.name + ": the cut changed the mass");
  physics::SymplecticEulerOptions so;
  so.enforce_stable_step = false;
  (void)physics::SymplecticEuler(so).step(m->system(), semi_implicit_h(*m));
}

void cut_ours(benchmark::State& st, const MeshCase& c, const std::vector<refine::Facet>& facets) {
  std::unique_ptr<MssModel<3>> m;
  std::uint32_t cut = 0;
  for (auto _ : st) {
    {
      Untimed pause(st);
      m.reset();  // free the previous model first: two 32³ models at once would only cost memory
      m = build_model(c);
      // a step first, so that the model is in the state a running simulation cuts it in
      // (pattern built, forces evaluated)
      physics::SymplecticEulerOptions so;
      so.enforce_stable_step = false;
      (void)physics::SymplecticEuler(so).step(m->system(), semi_implicit_h(*m));
    }
    cut = refine::cut(*m, facets).facets;
  }
  if (cut != facets.size()) st.SkipWithError("the cut did not unsew every selected face");
  st.counters["faces"] = static_cast<double>(facets.size());
}

// One semi-implicit step after a cut (the cut untimed): the topology-change work the step does.
void first_step_after_cut(benchmark::State& st, const MeshCase& c, const std::vector<refine::Facet>& facets) {
  physics::SymplecticEulerOptions so;
  so.enforce_stable_step = false;
  std::unique_ptr<MssModel<3>> m;
  double h = 0;
  for (auto _ : st) {
    physics::SymplecticEuler se(so);
    {
      Untimed pause(st);
      m.reset();
      m = build_model(c);
      h = semi_implicit_h(*m);
      (void)se.step(m->system(), h);
      (void)refine::cut(*m, facets);
    }
    (void)se.step(m->system(), h);
  }
  st.counters["faces"] = static_cast<double>(facets.size());
}

// The stable-step bound that a guarded run (enforce_stable_step, the default) recomputes after
// every cut and every 100 steps: one Gershgorin pass over the model's blocks.
void stable_step_bound(benchmark::State& st, const MeshCase& c) {
  const auto m = build_model(c);
  physics::SymplecticEulerOptions so;
  so.enforce_stable_step = false;
  (void)physics::SymplecticEuler(so).step(m->system(), semi_implicit_h(*m));
  for (auto _ : st) benchmark::DoNotOptimize(m->system().stable_step().h_max);
}

struct Restorable {
  std::unique_ptr<MssModel<3>> m;
  std::vector<double> x0, v0;
  explicit Restorable(const MeshCase& c) : m(build_model(c)) {
    x0.assign(m->nodes().x().begin(), m->nodes().x().end());
    v0.assign(m->nodes().v().begin(), m->nodes().v().end());
  }
  void restore() {
    std::copy(x0.begin(), x0.end(), m->nodes().x().begin());
    std::copy(v0.begin(), v0.end(), m->nodes().v().begin());
  }
};

void semi_implicit_steps(benchmark::State& st, const MeshCase& c, int steps_per_iteration) {
  const auto m = build_model(c);
  physics::SymplecticEulerOptions so;
  so.enforce_stable_step = false;
  physics::SymplecticEuler se(so);
  const double h = semi_implicit_h(*m);
  (void)se.step(m->system(), h);  // pattern built, as in a running simulation
  for (auto _ : st)
    for (int s = 0; s < steps_per_iteration; ++s) (void)se.step(m->system(), h);
}

void implicit_step(benchmark::State& st, const MeshCase& c) {
  Restorable r(c);
  physics::LinearlyImplicitEuler ie;
  ie.options().solver = physics::solve::Backend::jacobi;  // the table's unit; bench/results/solve.md has the others
  (void)ie.step(r.m->system(), kH);
  r.restore();
  ie.reset();
  int k = 0;
  double iterations = 0;
  for (auto _ : st) {
    iterations += ie.step(r.m->system(), kH).cg_iterations;
    if (++k == kImplicitReset) {
      Untimed pause(st);
      r.restore();
      ie.reset();
      k = 0;
    }
  }
  st.counters["cg_iterations"] = benchmark::Counter(iterations, benchmark::Counter::kAvgIterations);
}

MeshCase grid_case(const std::string& name, std::uint32_t nx, std::uint32_t ny, std::uint32_t nz, double a,
                   int rebuild_iterations) {
  GridSpec g;
  g.spacing = {a, a, a};
  // the middle plane across the longest axis (z for both grids), through the section's centre
  return {name, hex_grid(nx, ny, nz, g), Vec3d(nx * a / 2, ny * a / 2, (nz / 2) * a), Vec3d(0, 0, 1), 2,
          rebuild_iterations};
}

MeshCase frog_case(int rebuild_iterations) {
  constexpr double a = 2e-3;  // 2 mm cubes: a frog some 18 cm long from toes to head
  const auto* b = frog_body_cells;
  // the plane across the middle of the body, clamped by the belly (z = 0)
  return {"frog", frog_mesh(a), Vec3d((b[0] / 2) * a, b[1] * a / 2, b[2] * a / 2), Vec3d(1, 0, 0), 2, rebuild_iterations};
}

void register_all() {
  std::vector<MeshCase> cases;
  const Scale scale = sewn::bench::scale();
  if (scale == Scale::smoke) {
    cases.push_back(grid_case("hex4x4x6", 4, 4, 6, 0.0125, 2));
    (void)frog_mesh(2e-3);  // its count check runs in CI; cutting it takes too long for a smoke run
  } else {
    const int big = scale == Scale::full ? 4 : 1;
    cases.push_back(grid_case("hex8x8x10", 8, 8, 10, 0.0125, scale == Scale::full ? 40 : 10));
    cases.push_back(grid_case("hex32", 32, 32, 32, 0.1 / 32, big));
    cases.push_back(frog_case(big));
  }
  // the cases live as long as the benchmarks that refer to them
  static std::vector<std::shared_ptr<const MeshCase>> keep;
  for (MeshCase& mc : cases) {
    auto c = std::make_shared<const MeshCase>(std::move(mc));
    keep.push_back(c);
    auto sel = std::make_shared<const Selections>(select(*c));
    check_cut(*c, sel->one, "one");
    check_cut(*c, sel->ten, "ten");
    check_cut(*c, sel->plane, "plane");
    const std::string& n = c->name;
    const int it = c->rebuild_iterations;
    const std::string one_step = "1 semi-implicit step (ours/peer: the cut's cost in steps; goal for cut_1_face: < 1)";
    const std::string five_steps = "5 semi-implicit steps (goal for the 32³ beam's cut_plane: ours/peer < 1)";
    const std::string implicit = "1 implicit step";
    auto semi = [c](int steps) { return [c, steps](benchmark::State& st) { semi_implicit_steps(st, *c, steps); }; };

    ours(kSuite, n + "/cut_1_face", [c, sel](benchmark::State& st) { cut_ours(st, *c, sel->one); })
        ->Unit(benchmark::kMicrosecond)->Iterations(it);
    peer(kSuite, n + "/cut_1_face", one_step, semi(1))->Unit(benchmark::kMicrosecond);
    ours(kSuite, n + "/cut_10_faces", [c, sel](benchmark::State& st) { cut_ours(st, *c, sel->ten); })
        ->Unit(benchmark::kMicrosecond)->Iterations(it);
    peer(kSuite, n + "/cut_10_faces", one_step, semi(1))->Unit(benchmark::kMicrosecond);
    ours(kSuite, n + "/first_step_after_cut_1_face",
         [c, sel](benchmark::State& st) { first_step_after_cut(st, *c, sel->one); })
        ->Unit(benchmark::kMicrosecond)->Iterations(it);
    peer(kSuite, n + "/first_step_after_cut_1_face", one_step, semi(1))->Unit(benchmark::kMicrosecond);
    ours(kSuite, n + "/first_step_after_cut_plane",
         [c, sel](benchmark::State& st) { first_step_after_cut(st, *c, sel->plane); })
        ->Unit(benchmark::kMicrosecond)->Iterations(it);
    peer(kSuite, n + "/first_step_after_cut_plane", one_step, semi(1))->Unit(benchmark::kMicrosecond);
    ours(kSuite, n + "/stable_step_bound", [c](benchmark::State& st) { stable_step_bound(st, *c); })
        ->Unit(benchmark::kMicrosecond);
    peer(kSuite, n + "/stable_step_bound", one_step, semi(1))->Unit(benchmark::kMicrosecond);
    ours(kSuite, n + "/cut_plane", [c, sel](benchmark::State& st) { cut_ours(st, *c, sel->plane); })
        ->Unit(benchmark::kMicrosecond)->Iterations(it);
    peer(kSuite, n + "/cut_plane", five_steps, semi(5))->Unit(benchmark::kMicrosecond);
    ours(kSuite, n + "/cut_plane_vs_implicit", [c, sel](benchmark::State& st) { cut_ours(st, *c, sel->plane); })
        ->Unit(benchmark::kMicrosecond)->Iterations(it);
    peer(kSuite, n + "/cut_plane_vs_implicit", implicit, [c](benchmark::State& st) { implicit_step(st, *c); })
        ->Unit(benchmark::kMicrosecond);
  }
}

const Registration registration(&register_all);

}  // namespace
}  // namespace sewn::bench::cut
