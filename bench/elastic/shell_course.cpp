// bench_elastic, curved shells against published answers (issue 15): the Scordelis-Lo roof,
// the pinched hemisphere and the pinched cylinder of shell_course.hpp, per bending model and
// mesh,
//   elastic/shell_course/<case>/<bending>/<mesh>/n<n>
// (n cells per quarter side) with the displacement at the published load (linearised: the
// load scaled to a deflection of 1e-3 thickness and the answer scaled back), its error
// against the published answer,
// the change of displacement per unit load when the load is halved (the linearity check,
// a second solve outside the timing), and Newton's iterations.
#include <cmath>
#include <string>
#include <vector>

#include "shell_course.hpp"
#include "sewn_bench.hpp"

namespace bench_shell_course {
namespace {

using sewn::shell_course::Bending;
using sewn::shell_course::Case;
using sewn::shell_course::Mesh;

void course_row(benchmark::State& st, Case c, Mesh mesh, Bending bending, int n) {
  sewn::shell_course::Result r;
  double half = 0.0;
  for (auto _ : st) {
    try {
      r = sewn::shell_course::solve(c, mesh, bending, n);
      sewn::bench::Untimed pause(st);
      half = sewn::shell_course::solve(c, mesh, bending, n, 0.5).displacement;
    } catch (const std::exception& e) {
      st.SkipWithError((std::string(sewn::shell_course::case_name(c)) + " n=" + std::to_string(n) + ": " + e.what()).c_str());
      return;
    }
  }
  const double exact = sewn::shell_course::reference(c);
  st.counters["displacement"] = r.displacement;
  st.counters["reference"] = exact;
  st.counters["error vs reference %"] = 100.0 * std::abs(r.displacement - exact) / exact;
  st.counters["load halved, change %"] = 100.0 * std::abs(half - r.displacement) / std::abs(r.displacement);
  st.counters["Newton iterations"] = r.newton;
  st.counters["_triangles"] = static_cast<double>(r.triangles);
}

void register_all() {
  using sewn::bench::Scale;
  const Scale scale = sewn::bench::scale();
  const std::vector<int> sizes = scale == Scale::smoke ? std::vector<int>{4} : scale == Scale::small ? std::vector<int>{4, 8, 16}
                                                                                                     : std::vector<int>{4, 8, 16, 32};
  for (Case c : {Case::roof, Case::hemisphere, Case::cylinder})
    for (Bending bending : {Bending::morley, Bending::patch, Bending::hinge})
      for (Mesh mesh : {Mesh::structured, Mesh::jittered})
        for (int n : sizes) {
          auto* row = sewn::bench::ours("elastic",
                                        std::string("shell_course/") + sewn::shell_course::case_name(c) + "/" +
                                            sewn::shell_course::bending_name(bending) + "/" +
                                            sewn::shell_course::mesh_name(mesh) + "/n" + std::to_string(n),
                                        [=](benchmark::State& st) { course_row(st, c, mesh, bending, n); });
          row->Iterations(1);
          // the n = 32 solves take 0.3-3.5 s each (and a second, untimed, for the linearity
          // check): one repetition, not the full run's ten, keeps the suite's run short
          if (n >= 32) row->Repetitions(1);
        }
}

const sewn::bench::Registration reg(&register_all);

}  // namespace
}  // namespace bench_shell_course
