// The solver layer across cuts: a cut changes the Jacobian's pattern, and every backend must
// notice it by itself (new analysis, new factorization) and keep solving the right system.
#include <doctest/doctest.h>

#include <cmath>
#include <memory>

#include "sewn/physics/integrators.hpp"
#include "sewn/physics/solve/linear_solver.hpp"
#include "sewn/refine/cut.hpp"

namespace test_solve_cut {

using namespace sewn;
using namespace sewn::physics;
using namespace sewn::refine;
using Eigen::Vector3d;

namespace {

// A 2x2x8 beam of 1.25 cm cubes clamped at z = 0, stepped at h = 1 ms; its section at mid
// height is cut three quarters through after 10 steps (3 of its 4 faces); positions after 30.
Eigen::VectorXd run(solve::Backend b, double tolerance, double floor, int* analyses_at_cut) {
  const double a = 0.0125;
  MssModel<3> m(hex_grid(2, 2, 8, {{a, a, a}, {}}), {{100e6, 0.3, 1000}}, {});
  for (Index i = 0; i < m.nodes().size(); ++i)
    if (m.rest_position(i).z() <= 1e-12) m.nodes().fix(i);
  ImplicitEulerOptions o;
  o.solver = b;
  o.cg_tolerance = tolerance;
  o.cg_absolute_tolerance = floor;
  LinearlyImplicitEuler ie(o);
  for (int s = 0; s < 30; ++s) {
    if (s == 10) {
      auto facets = facets_across_plane(m, Vector3d(0, 0, 4 * a), Vector3d(0, 0, 1));
      REQUIRE(facets.size() == 4);
      facets.pop_back();
      cut(m, std::span(facets));
      REQUIRE(m.map().validate().ok());
    }
    const StepReport r = ie.step(m.system(), 1e-3);
    REQUIRE(r.cg_converged);
    if (s == 0 || s == 10) *analyses_at_cut += r.solve.symbolic_analyses;
    if (s != 0 && s != 10) CHECK(r.solve.symbolic_analyses == 0);
  }
  Eigen::VectorXd x(3 * Eigen::Index{m.nodes().size()});
  for (Index i = 0; i < m.nodes().size(); ++i) x.segment<3>(3 * i) = m.nodes().position(i) - m.rest_position(i);
  return x;
}

}  // namespace

TEST_CASE("every solver backend notices a cut and follows a tight solve through it") {
  int ignored = 0;
  const Eigen::VectorXd ref = run(solve::Backend::jacobi, 1e-12, 0.0, &ignored);
  REQUIRE(ref.norm() > 0);
  for (auto b : solve::available_backends()) {
    CAPTURE(solve::to_string(b));
    int analyses = 0;
    const Eigen::VectorXd x = run(b, 1e-6, solve::default_absolute_tolerance, &analyses);
    if (b != solve::Backend::jacobi) CHECK(analyses == 2);  // before the first step and after the cut
    CHECK((x - ref).norm() <= 30 * 1e-6 * ref.norm());
  }
}

}  // namespace test_solve_cut
