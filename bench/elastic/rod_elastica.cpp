// bench_elastic, the rod against its continuum answer (issue 15): the pure-moment cantilever
// of PHYSICS_NOTES §4 rods (c), a rod of length 1 m bent by an end moment M = 3EI/L into an
// arc of the elastica circle (its tip edge turned by 3 rad), solved statically in a load ramp
// of 6 steps (rods::solve_static), per number of segments:
//   elastic/rod_elastica/seg<n>
// with the tip's distance from the circle's, over L, measured from the clamped edge's midpoint
// (where the rod's clamped section sits: second order) and from the first node (first order,
// the clamp misplaced by half an edge).
#include <cmath>
#include <string>

#include "sewn/physics/rods/static_solve.hpp"
#include "sewn_bench.hpp"

namespace bench_rod_elastica {
namespace {

namespace rods = sewn::physics::rods;
using rods::Points;
using rods::Vec3;

void elastica(benchmark::State& st, int segments) {
  const rods::Section sec = rods::Section::circular(1e7, 0.3, 0.01);
  const double L = 1.0, M = 3.0 * sec.EI1 / L, Rc = sec.EI1 / M;
  const int n = segments + 1;
  auto arc_tip = [&](double start, double length) { return Vec3(start + Rc * std::sin(length / Rc), Rc * (1 - std::cos(length / Rc)), 0); };
  Points x(3, n);
  for (auto _ : st) {
    for (int i = 0; i < n; ++i) x.col(i) = Vec3(L * i / (n - 1), 0, 0);
    rods::Rod rod(x, false, sec);
    rod.fix_theta(0);
    rods::StaticProblem p;
    p.fixed.assign(static_cast<std::size_t>(n), sewn::physics::no_axes);
    p.fixed[0] = p.fixed[1] = sewn::physics::all_axes;
    for (int i = 2; i < n; ++i) p.fixed[static_cast<std::size_t>(i)] = sewn::physics::axis_z;  // planar
    try {
      for (int step = 1; step <= 6; ++step) {
        p.moments = {{n - 2, Vec3(0, 0, 1), M * step / 6}};
        (void)rods::solve_static(rod, x, p);
      }
    } catch (const std::exception& e) {
      st.SkipWithError((std::string("rod elastica: ") + e.what()).c_str());
      return;
    }
  }
  const double l = L / segments;
  st.counters["error vs elastica %"] = 100.0 * (x.col(n - 1) - arc_tip(l / 2, L - l / 2)).norm() / L;
  st.counters["error from the first node %"] = 100.0 * (x.col(n - 1) - arc_tip(0, L)).norm() / L;
  st.counters["_segments"] = segments;
}

void register_all() {
  using sewn::bench::Scale;
  const Scale scale = sewn::bench::scale();
  const std::vector<int> sizes = scale == Scale::smoke ? std::vector<int>{10} : scale == Scale::small ? std::vector<int>{10, 20, 40}
                                                                                                       : std::vector<int>{10, 20, 40, 80};
  for (int s : sizes)
    sewn::bench::ours("elastic", "rod_elastica/seg" + std::to_string(s), [s](benchmark::State& st) { elastica(st, s); })->Iterations(1);
}

const sewn::bench::Registration reg(&register_all);

}  // namespace
}  // namespace bench_rod_elastica
