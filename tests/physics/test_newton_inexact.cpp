// NewtonEuler's cheaper evaluations: Rayleigh damping's F(q, v) - F(q, 0) from the
// velocity-dependent terms only (ForceTerm::velocity_dependent), and inexact Newton with
// Eisenstat-Walker forcing terms on the kept-factorization PCG (cg_forcing_max).

#include <doctest/doctest.h>

#include <algorithm>
#include <cmath>
#include <random>
#include <vector>

#include "elastic_helpers.hpp"
#include "sewn/physics/basic_terms.hpp"
#include "sewn/physics/integrate/newton_euler.hpp"
#include "sewn/physics/solve/linear_solver.hpp"

namespace test_newton_inexact {
namespace {

namespace ph = sewn::physics;
using Eigen::Vector3d;

// A soft tetrahedral cantilever (4 × 1 × 1 cubes of 5 cm) clamped at x = 0, under gravity
// with Rayleigh α damping, started with a downward swing.
void build_cantilever(ph::System& sys) {
  const ph::test::TetMesh box = ph::test::kuhn_box(4, 1, 1, 0.2, 0.05, 0.05);
  ph::test::add_tets(sys, box, ph::solids::TetLaw::stable_neo_hookean, 2e5, 0.3, 1000.0);
  for (ph::Index i = 0; i < sys.nodes().size(); ++i) {
    if (box.x[i].x() == 0.0) sys.nodes().fix(i);
    else sys.nodes().set_velocity(i, Vector3d(0.0, 0.0, -2.0 * box.x[i].x()));
  }
  sys.add<ph::Gravity>(Vector3d(0.0, 0.0, -9.81));
  sys.add<ph::MassDamping>(2.0);
}

std::vector<double> forces(const ph::ForceTerm& t, const ph::System& sys, std::span<const double> v) {
  std::vector<double> f(sys.nodes().x().size(), 0.0);
  const ph::StateView s{sys.nodes().x(), v, sys.nodes().masses()};
  t.add_forces(s, f);
  return f;
}

// The backward-Euler residual M (v - v_n)/h - F(x, v) on the free axes, with every term's
// forces from System::add_forces at the new state: what Newton's gradient must have zeroed.
double residual(const ph::System& sys, const std::vector<double>& v_before, double h) {
  const auto x = sys.nodes().x(), v = sys.nodes().v();
  std::vector<double> f(x.size(), 0.0);
  sys.add_forces(sys.nodes().state(), f);
  double worst = 0.0;
  for (std::size_t k = 0; k < x.size(); ++k) {
    if (sys.nodes().fixed_masks()[k / 3] >> (k % 3) & 1) continue;
    worst = std::max(worst, std::abs(sys.nodes().masses()[k / 3] * (v[k] - v_before[k]) / h - f[k]));
  }
  return worst;
}

TEST_CASE("a term that declares velocity-independent forces has the same forces at any velocity") {
  ph::System sys;
  build_cantilever(sys);
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(-3.0, 3.0);
  std::vector<double> v(sys.nodes().x().size()), zero(v.size(), 0.0);
  for (auto& a : v) a = u(rng);
  int independent = 0;
  for (const auto& t : sys.terms()) {
    CAPTURE(t->name());
    if (t->velocity_dependent()) continue;
    ++independent;
    CHECK(forces(*t, sys, v) == forces(*t, sys, zero));
  }
  CHECK(independent == 2);  // the tets and gravity; the damping must say it depends
  const auto damping = std::find_if(sys.terms().begin(), sys.terms().end(), [](const auto& t) { return t->name() == "mass damping"; });
  REQUIRE(damping != sys.terms().end());
  CHECK((*damping)->velocity_dependent());
  CHECK(forces(**damping, sys, v) != forces(**damping, sys, zero));
}

TEST_CASE("damped Newton steps zero the backward-Euler residual of all the forces") {
  ph::System sys;
  build_cantilever(sys);
  ph::integrate::NewtonEulerOptions opt;
  opt.solver = ph::integrate::LinearSolver::ldlt;
  opt.velocity_tolerance = 1e-9;
  ph::integrate::NewtonEuler newton(opt);
  const double h = 1.0 / 30.0;
  for (int n = 0; n < 5; ++n) {
    const std::vector<double> v_before(sys.nodes().v().begin(), sys.nodes().v().end());
    const auto rep = newton.step(sys, h);
    CAPTURE(n);
    CAPTURE(rep.iterations);
    // The last Newton update moved no node by more than 1e-9 m/s × h; the residual it leaves
    // is that update times the Newton matrix: ~(m/h² + k) · 3e-11 m, far below the forces (~1e-2 N).
    CHECK(residual(sys, v_before, h) < 1e-6);
  }
}

TEST_CASE("inexact Newton (forcing terms) on cholmod-pcg: the same trajectory within the Newton tolerance, fewer CG iterations") {
  if (!ph::solve::available(ph::solve::Backend::cholmod_pcg)) return;  // needs CHOLMOD
  const double h = 1.0 / 30.0, tol = 1e-4;
  ph::System exact, loose;
  build_cantilever(exact);
  build_cantilever(loose);
  ph::integrate::NewtonEulerOptions opt;
  opt.solver = ph::integrate::LinearSolver::cholmod_pcg;
  opt.velocity_tolerance = tol;
  opt.cg_tolerance = 1e-8;
  ph::integrate::NewtonEuler a(opt);
  opt.cg_forcing_max = 0.5;
  ph::integrate::NewtonEuler b(opt);
  int cg_a = 0, cg_b = 0, refinements = 0;
  const int steps = 10;
  for (int n = 0; n < steps; ++n) {
    cg_a += a.step(exact, h).linear_iterations;
    const auto rb = b.step(loose, h);
    cg_b += rb.linear_iterations;
    refinements += rb.forcing_refinements;
  }
  double diff = 0.0;
  for (std::size_t k = 0; k < exact.nodes().x().size(); ++k) diff = std::max(diff, std::abs(exact.nodes().x()[k] - loose.nodes().x()[k]));
  MESSAGE("forcing terms: " << cg_b << " CG iterations against " << cg_a << " at a fixed 1e-8; " << refinements
                            << " final solves refined; largest node difference " << diff << " m");
  // Each step stops within tol × h of its solution in either run.
  CHECK(diff < 2.0 * steps * tol * h);
  CHECK(cg_b < cg_a);
  CHECK(refinements > 0);
}

}  // namespace
}  // namespace test_newton_inexact
