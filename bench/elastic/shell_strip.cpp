// bench_elastic, the shell against its continuum answer (issue 15): the plate strip cantilever
// of shell_strip.hpp under its own weight, per bending model and mesh,
//   elastic/shell_strip/<bending>/<mesh>/nx<n>
// with the tip, its error against Euler–Bernoulli and Newton's iterations. The error falls at
// second order under refinement for `morley` on every mesh and for `patch` on the structured
// ones only; `hinge` (k_B = D/6) does not converge on these meshes (docs/elastic.md).
#include <string>
#include <vector>

#include "shell_strip.hpp"
#include "sewn_bench.hpp"

namespace bench_shell_strip {
namespace {

using sewn::shell_strip::Bending;
using sewn::shell_strip::Mesh;

void strip_tip(benchmark::State& st, Mesh mesh, Bending bending, int nx) {
  sewn::shell_strip::Result r;
  for (auto _ : st) {
    try {
      r = sewn::shell_strip::solve(mesh, bending, nx);
    } catch (const std::exception& e) {
      st.SkipWithError((std::string("shell strip nx=") + std::to_string(nx) + ": " + e.what()).c_str());
      return;
    }
  }
  const double exact = sewn::shell_strip::euler_bernoulli_m();
  st.counters["tip mm"] = 1e3 * r.tip_m;
  st.counters["Euler-Bernoulli mm"] = 1e3 * exact;
  st.counters["error vs Euler-Bernoulli %"] = 100.0 * std::abs(r.tip_m - exact) / exact;
  st.counters["Newton iterations"] = r.newton;
  st.counters["_triangles"] = static_cast<double>(r.triangles);
}

void register_all() {
  using sewn::bench::Scale;
  const Scale scale = sewn::bench::scale();
  const std::vector<int> sizes = scale == Scale::smoke ? std::vector<int>{10} : scale == Scale::small ? std::vector<int>{10, 20, 40}
                                                                                                       : std::vector<int>{10, 20, 40, 80};
  for (Bending bending : {Bending::morley, Bending::patch, Bending::hinge})
    for (Mesh mesh : {Mesh::square, Mesh::flipped, Mesh::row, Mesh::jittered, Mesh::diagonals, Mesh::offset})
      for (int nx : sizes)
        sewn::bench::ours("elastic",
                          std::string("shell_strip/") + sewn::shell_strip::bending_name(bending) + "/" +
                              sewn::shell_strip::mesh_name(mesh) + "/nx" + std::to_string(nx),
                          [=](benchmark::State& st) { strip_tip(st, mesh, bending, nx); })
            ->Iterations(1);
}

const sewn::bench::Registration reg(&register_all);

}  // namespace
}  // namespace bench_shell_strip
