// Dissipation potentials (ForceTerm::dissipation) of every velocity-dependent term: mass
// damping, per-spring viscosity, Rayleigh's stiffness-proportional damping and smoothed
// Coulomb friction. Their velocity gradients and Hessians against the forces and Jacobians the
// terms already have, by finite differences; and NewtonEuler refusing a velocity-dependent term
// that has none.

#include <doctest/doctest.h>

#include <cmath>
#include <functional>
#include <random>
#include <string>
#include <vector>

#include <Eigen/Eigenvalues>

#include "helpers.hpp"
#include "sewn/physics/basic_terms.hpp"
#include "sewn/physics/integrate/newton_euler.hpp"
#include "sewn/physics/obstacles/obstacles.hpp"

namespace test_dissipation {
namespace {

namespace ph = sewn::physics;
using Eigen::Vector3d;

// Ψ of the system's only term at its current state.
double psi(const ph::System& sys) { return sys.terms().front()->dissipation(sys.nodes().state()); }

// F(x, v) - F(x, 0) of the system: its velocity-dependent forces.
Eigen::VectorXd damping_forces(ph::System& sys) {
  const Eigen::VectorXd f = ph::test::forces(sys);
  auto v = sys.nodes().v();
  const std::vector<double> keep(v.begin(), v.end());
  std::fill(v.begin(), v.end(), 0.0);
  const Eigen::VectorXd f0 = ph::test::forces(sys);
  std::copy(keep.begin(), keep.end(), v.begin());
  return f - f0;
}

// Checks, for the system's one term at its current state: Ψ(x, 0) = 0 ≤ Ψ(x, v); the velocity
// gradient of Ψ by central differences against minus the damping forces; Ψ's second
// differences against minus the assembled ∂F/∂v, which is positive semidefinite.
void check_potential(ph::System& sys, double delta) {
  REQUIRE(sys.terms().size() == 1);
  REQUIRE(sys.terms().front()->dissipative());
  auto v = sys.nodes().v();
  const Eigen::Index n = static_cast<Eigen::Index>(v.size());
  const double value = psi(sys);
  CHECK(value > 0.0);
  {
    const std::vector<double> keep(v.begin(), v.end());
    std::fill(v.begin(), v.end(), 0.0);
    CHECK(psi(sys) == 0.0);
    std::copy(keep.begin(), keep.end(), v.begin());
  }
  // ψ at v + a δ e_i + b δ e_j.
  const auto shifted = [&](Eigen::Index i, double a, Eigen::Index j, double b) {
    const double vi = v[static_cast<std::size_t>(i)], vj = v[static_cast<std::size_t>(j)];
    v[static_cast<std::size_t>(i)] += a * delta;
    v[static_cast<std::size_t>(j)] += b * delta;
    const double out = psi(sys);
    v[static_cast<std::size_t>(i)] = vi;
    v[static_cast<std::size_t>(j)] = vj;
    return out;
  };
  const Eigen::VectorXd fd = damping_forces(sys);
  Eigen::VectorXd grad(n);
  Eigen::MatrixXd hess(n, n);
  for (Eigen::Index i = 0; i < n; ++i) {
    grad[i] = (shifted(i, 1, i, 0) - shifted(i, -1, i, 0)) / (2 * delta);
    for (Eigen::Index j = 0; j < n; ++j)
      hess(i, j) = (shifted(i, 1, j, 1) - shifted(i, 1, j, -1) - shifted(i, -1, j, 1) + shifted(i, -1, j, -1)) / (4 * delta * delta);
  }
  const Eigen::MatrixXd Cv = ph::test::assembled(sys, 0.0, 1.0, {});
  CAPTURE(value);
  CHECK(fd.norm() > 0.0);
  CHECK((grad + fd).cwiseAbs().maxCoeff() < 1e-6 * fd.cwiseAbs().maxCoeff());
  CHECK((hess + Cv).cwiseAbs().maxCoeff() < 1e-5 * Cv.cwiseAbs().maxCoeff());
  CHECK(Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd>(-Cv).eigenvalues().minCoeff() > -1e-10 * Cv.norm());
}

// n nodes at random positions in the unit cube with random velocities (of size `speed`).
void random_nodes(ph::System& sys, int n, double speed, std::mt19937& rng) {
  std::uniform_real_distribution<double> u(-1.0, 1.0), m(0.5, 2.0);
  for (int i = 0; i < n; ++i)
    (void)sys.nodes().add(Vector3d(u(rng), u(rng), u(rng)), speed * Vector3d(u(rng), u(rng), u(rng)), m(rng));
}

// Springs between consecutive nodes and a few across, rest lengths from 0.5 to 1.5 times the
// current length: some stretched, some compressed (Rayleigh's clamp at work).
void random_springs(ph::Springs& springs, const ph::System& sys, std::mt19937& rng) {
  std::uniform_real_distribution<double> ratio(0.5, 1.5), k(10.0, 100.0), gamma(0.1, 2.0);
  const ph::Index n = sys.nodes().size();
  for (ph::Index i = 0; i < n; ++i)
    for (const ph::Index j : {(i + 1) % n, (i + 3) % n}) {
      const double d = (sys.nodes().position(j) - sys.nodes().position(i)).norm();
      (void)springs.add(i, j, k(rng), ratio(rng) * d, ph::SpringKind::edge, gamma(rng));
    }
}

TEST_CASE("dissipation potentials: gradient and Hessian in v are minus the damping forces and their Jacobian") {
  std::mt19937 rng(15);
  SUBCASE("mass damping") {
    ph::System sys;
    random_nodes(sys, 4, 1.0, rng);
    (void)sys.add<ph::MassDamping>(3.0);
    check_potential(sys, 1e-4);
  }
  SUBCASE("per-spring viscosity") {
    ph::System sys;
    random_nodes(sys, 6, 1.0, rng);
    random_springs(sys.add<ph::Springs>(ph::SpringDamping::viscous), sys, rng);
    check_potential(sys, 1e-4);
  }
  SUBCASE("Rayleigh stiffness-proportional damping") {
    ph::System sys;
    random_nodes(sys, 6, 1.0, rng);
    random_springs(sys.add<ph::Springs>(ph::SpringDamping::stiffness_proportional, 0.02), sys, rng);
    check_potential(sys, 1e-4);
  }
  SUBCASE("smoothed Coulomb friction, below and above its velocity scale") {
    // Nodes below a tilted plane, tangential speeds from 0 to ~3 ε_v: both branches of f1.
    const double eps_v = 0.5;
    for (const double speed : {0.1, 0.4, 1.5}) {
      CAPTURE(speed);
      ph::System sys;
      random_nodes(sys, 5, speed, rng);
      auto& obs = sys.add<ph::obstacles::Obstacles>(1e3, eps_v);
      (void)obs.add(ph::obstacles::Plane{Vector3d(0, 0, 1.5), Vector3d(0.2, -0.1, 1).normalized(), 0.6});
      check_potential(sys, 1e-5);
    }
  }
}

// A drag F = -c |v| v: velocity-dependent, with a potential it does not declare.
class UndeclaredDrag final : public ph::ForceTerm {
 public:
  [[nodiscard]] std::string_view name() const override { return "undeclared drag"; }
  void add_forces(const ph::StateView& s, std::span<double> f) const override {
    for (ph::Index i = 0; i < s.size(); ++i) {
      const Vector3d v(s.v[3 * i], s.v[3 * i + 1], s.v[3 * i + 2]);
      for (int a = 0; a < 3; ++a) f[3 * i + static_cast<std::size_t>(a)] -= 0.1 * v.norm() * v[a];
    }
  }
  [[nodiscard]] double potential_energy(const ph::StateView& /*s*/) const override { return 0.0; }
};

TEST_CASE("Newton refuses a term whose forces depend on velocity without a dissipation potential, state unchanged") {
  ph::System sys;
  const ph::Index i = sys.nodes().add(Vector3d(0, 0, 0), Vector3d(1, 0, 0), 1.0);
  (void)sys.add<ph::Gravity>(Vector3d(0, 0, -9.81));
  (void)sys.add<UndeclaredDrag>();
  ph::integrate::NewtonEuler newton;
  CHECK_THROWS_WITH_AS((void)newton.step(sys, 1e-2), doctest::Contains("undeclared drag"), ph::InputError);
  CHECK(sys.nodes().position(i) == Vector3d(0, 0, 0));
  CHECK(sys.nodes().velocity(i) == Vector3d(1, 0, 0));
}

}  // namespace
}  // namespace test_dissipation
