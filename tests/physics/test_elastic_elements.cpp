// Per-element elasticity (solids/tet_element, shells/membrane_element, shells/hinge_element):
// gradients and Hessians against central finite differences on random and near-degenerate
// inputs (slivers, nearly flat hinges), zero force under rigid motions, zero net force and
// torque per stencil, the PSD projection, and the force terms' assembly into the block pattern.
#include <doctest/doctest.h>

#include <cmath>
#include <numbers>
#include <random>

#include <Eigen/Eigenvalues>

#include "elastic_helpers.hpp"
#include "helpers.hpp"
#include "sewn/physics/shells/shell_terms.hpp"
#include "sewn/physics/solids/tets.hpp"

namespace test_elastic_elements {

using namespace sewn::physics;
using namespace sewn::physics::test;
using Eigen::Matrix3d;
using Eigen::Vector3d;

namespace {

const solids::Lame lame{0.7, 1.3};

}  // namespace

TEST_CASE("tet elasticity: StVK and stable neo-Hookean gradients and Hessians match finite differences") {
  std::mt19937 rng(15);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  for (const auto law : {solids::TetLaw::stvk, solids::TetLaw::stable_neo_hookean}) {
    CAPTURE(static_cast<int>(law));
    for (int trial = 0; trial < 20; ++trial) {
      solids::TetPositions X;
      X << 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1;
      X += 0.2 * solids::TetPositions::NullaryExpr([&] { return u(rng); });
      const solids::TetRest rest = solids::tet_rest(X);
      // Deformations up to 40%, and inverted ones (a node pushed through its opposite face).
      solids::TetPositions x = X + 0.4 * solids::TetPositions::NullaryExpr([&] { return u(rng); });
      if (trial % 4 == 3) x.col(3) = -x.col(3);
      check_element<4>([&](const solids::TetPositions& y) { return solids::tet_energy(law, y, rest, lame); },
                       [&](const solids::TetPositions& y) { return solids::tet_gradient(law, y, rest, lame); },
                       [&](const solids::TetPositions& y) { return solids::tet_hessian(law, y, rest, lame); }, x, 1e-5,
                       1e-6);
    }
    // A sliver: the fourth node 1e-3 above the base plane.
    solids::TetPositions S;
    S << 0, 1, 0, 0.3, 0, 0, 1, 0.3, 0, 0, 0, 1e-3;
    const solids::TetRest rest = solids::tet_rest(S);
    solids::TetPositions x = S;
    x(2, 3) = 1.5e-3;
    x(0, 1) = 1.1;
    check_element<4>([&](const solids::TetPositions& y) { return solids::tet_energy(law, y, rest, lame); },
                     [&](const solids::TetPositions& y) { return solids::tet_gradient(law, y, rest, lame); },
                     [&](const solids::TetPositions& y) { return solids::tet_hessian(law, y, rest, lame); }, x, 1e-8,
                     1e-5);
  }
}

TEST_CASE("tet elasticity: rigid motions give zero energy and force; StVK's reflection has zero energy, neo-Hookean's does not") {
  std::mt19937 rng(16);
  solids::TetPositions X;
  X << 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1;
  const solids::TetRest rest = solids::tet_rest(X);
  const double g_scale = solids::tet_gradient(solids::TetLaw::stvk, 1.1 * X, rest, lame).cwiseAbs().maxCoeff();
  for (const auto law : {solids::TetLaw::stvk, solids::TetLaw::stable_neo_hookean}) {
    for (int k = 0; k < 10; ++k) {
      const Matrix3d R = random_rotation(rng);
      const solids::TetPositions x = (R * X).colwise() + Vector3d(3.0, -2.0, 5.0);
      CHECK(std::abs(solids::tet_energy(law, x, rest, lame)) < 1e-13);
      CHECK(solids::tet_gradient(law, x, rest, lame).cwiseAbs().maxCoeff() < 1e-12 * g_scale);
    }
  }
  // Node 3 mirrored through the base plane: F = diag(1, 1, -1), a reflection.
  solids::TetPositions x = X;
  x(2, 3) = -1.0;
  CHECK(std::abs(solids::tet_energy(solids::TetLaw::stvk, x, rest, lame)) < 1e-15);
  CHECK(solids::tet_gradient(solids::TetLaw::stvk, x, rest, lame).norm() < 1e-14);
  // Stable neo-Hookean: ½λ'((J - α)² - (1 - α)²) at J = -1, > 0, and a gradient that pushes node 3 up.
  const double lp = lame.lambda + lame.mu, alpha = 1.0 + lame.mu / lp;
  const double expect = rest.volume * 0.5 * lp * ((1.0 + alpha) * (1.0 + alpha) - (1.0 - alpha) * (1.0 - alpha));
  CHECK(expect > 0.0);
  CHECK(solids::tet_energy(solids::TetLaw::stable_neo_hookean, x, rest, lame) == doctest::Approx(expect));
  CHECK(solids::tet_gradient(solids::TetLaw::stable_neo_hookean, x, rest, lame)[11] < 0.0);
}

TEST_CASE("tet elasticity: both laws linearise to the same Lamé constants at rest") {
  // d²Ψ/dF² at F = I is μ(δ_ik δ_jl + δ_il δ_jk) + λ δ_ij δ_kl for both laws.
  const auto D1 = solids::piola_derivative(solids::TetLaw::stvk, Matrix3d::Identity(), lame);
  const auto D2 = solids::piola_derivative(solids::TetLaw::stable_neo_hookean, Matrix3d::Identity(), lame);
  elements::Mat<9> expect = elements::Mat<9>::Zero();
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j)
      for (int k = 0; k < 3; ++k)
        for (int l = 0; l < 3; ++l)
          expect(i + 3 * j, k + 3 * l) =
              lame.mu * ((i == k && j == l) + (i == l && j == k)) + lame.lambda * (i == j && k == l);
  CHECK((D1 - expect).cwiseAbs().maxCoeff() < 1e-14);
  CHECK((D2 - expect).cwiseAbs().maxCoeff() < 1e-14);
  CHECK(solids::first_piola(solids::TetLaw::stable_neo_hookean, Matrix3d::Identity(), lame).norm() < 1e-15);
}

TEST_CASE("CST membrane: gradient and Hessian match finite differences; rigid motions give zero force") {
  std::mt19937 rng(17);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  const auto mat = shells::membrane_material(2.0, 0.3, 0.05);
  for (int trial = 0; trial < 20; ++trial) {
    shells::TriPositions X;
    X << 0, 1, 0, 0, 0, 1, 0, 0, 0;
    X += 0.2 * shells::TriPositions::NullaryExpr([&] { return u(rng); });
    const shells::TriRest rest = shells::tri_rest(X);
    const shells::TriPositions x = X + 0.4 * shells::TriPositions::NullaryExpr([&] { return u(rng); });
    check_element<3>([&](const shells::TriPositions& y) { return shells::membrane_energy(y, rest, mat); },
                     [&](const shells::TriPositions& y) { return shells::membrane_gradient(y, rest, mat); },
                     [&](const shells::TriPositions& y) { return shells::membrane_hessian(y, rest, mat); }, x, 1e-5, 1e-6);
    const double g_scale = shells::membrane_gradient(1.1 * X, rest, mat).cwiseAbs().maxCoeff();
    const shells::TriPositions moved = (random_rotation(rng) * X).colwise() + Vector3d(1.0, 2.0, 3.0);
    CHECK(std::abs(shells::membrane_energy(moved, rest, mat)) < 1e-14);
    CHECK(shells::membrane_gradient(moved, rest, mat).cwiseAbs().maxCoeff() < 1e-12 * g_scale);
  }
  // A sliver triangle (height 1e-3 of its base).
  shells::TriPositions S;
  S << 0, 1, 0.4, 0, 0, 1e-3, 0, 0, 0;
  const shells::TriRest rest = shells::tri_rest(S);
  shells::TriPositions x = S;
  x(1, 2) = 2e-3;
  x(2, 2) = 5e-4;
  check_element<3>([&](const shells::TriPositions& y) { return shells::membrane_energy(y, rest, mat); },
                   [&](const shells::TriPositions& y) { return shells::membrane_gradient(y, rest, mat); },
                   [&](const shells::TriPositions& y) { return shells::membrane_hessian(y, rest, mat); }, x, 1e-8, 1e-5);
}

TEST_CASE("hinge bending: angle, gradient and Hessian match finite differences, nearly flat hinges included") {
  std::mt19937 rng(18);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  const double kb = shells::hinge_stiffness(1e3, 0.3, 0.01);
  auto hinge = [](double fold) {
    // Edge along y from (0,0,0) to (0,1,0); wings at x = ∓1, folded by `fold` each.
    shells::HingePositions X;
    X.col(0) = Vector3d(-std::cos(fold), 0.4, std::sin(fold));
    X.col(1) = Vector3d(0, 0, 0);
    X.col(2) = Vector3d(0, 1, 0);
    X.col(3) = Vector3d(std::cos(fold), 0.6, std::sin(fold));
    return X;
  };
  // θ against the construction: both wings lifted by `fold` bend the hinge by 2·fold.
  CHECK(std::abs(shells::dihedral_angle(hinge(0.3))) == doctest::Approx(0.6));
  CHECK(shells::dihedral_angle(hinge(0.0)) == doctest::Approx(0.0).scale(1e-15));
  for (const double fold : {0.0, 1e-7, 0.3, 1.2}) {
    CAPTURE(fold);
    const shells::HingePositions X = hinge(fold);
    const shells::HingeRest rest = shells::hinge_rest(hinge(0.1));
    const shells::HingePositions x = X + 0.05 * shells::HingePositions::NullaryExpr([&] { return u(rng); });
    const auto theta = [](const shells::HingePositions& y) { return shells::dihedral_angle(y); };
    CHECK(rel_err(shells::dihedral_gradient(x), fd_gradient<shells::HingePositions>(theta, x, 1e-6)) < 1e-7);
    check_element<4>([&](const shells::HingePositions& y) { return shells::hinge_energy(y, rest, kb); },
                     [&](const shells::HingePositions& y) { return shells::hinge_gradient(y, rest, kb); },
                     [&](const shells::HingePositions& y) { return shells::hinge_hessian(y, rest, kb); }, x, 1e-6, 1e-6);
    // Exactly flat (no noise): the fold's own derivative must still be right.
    check_element<4>([&](const shells::HingePositions& y) { return shells::hinge_energy(y, rest, kb); },
                     [&](const shells::HingePositions& y) { return shells::hinge_gradient(y, rest, kb); },
                     [&](const shells::HingePositions& y) { return shells::hinge_hessian(y, rest, kb); }, X, 1e-6, 1e-6);
  }
  // Rigid motions of the rest shape: zero energy and force.
  const shells::HingePositions X = hinge(0.4);
  const shells::HingeRest rest = shells::hinge_rest(X);
  const double g_scale = shells::hinge_gradient(hinge(0.5), rest, kb).cwiseAbs().maxCoeff();
  for (int k = 0; k < 10; ++k) {
    const shells::HingePositions x = (random_rotation(rng) * X).colwise() + Vector3d(-1.0, 0.5, 2.0);
    CHECK(shells::hinge_energy(x, rest, kb) < 1e-24);
    CHECK(shells::hinge_gradient(x, rest, kb).cwiseAbs().maxCoeff() < 1e-12 * g_scale);
  }
}

TEST_CASE("hinge bending: the closed-form angle Hessian matches differences of the angle gradient on random hinges") {
  // Random hinges, wings leaning past the edge's ends included (s_A, s_B outside [0, 1]), at
  // several scales: ∇²θ against central differences of ∇θ.
  std::mt19937 rng(181);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  for (int trial = 0; trial < 40; ++trial) {
    CAPTURE(trial);
    const double scale = std::pow(10.0, u(rng) * 2.0);
    shells::HingePositions x;
    x.col(1) = Vector3d(0, 0, 0);
    x.col(2) = Vector3d(0, 1, 0);
    x.col(0) = Vector3d(-1.0, 1.5 * u(rng) + 0.5, 0.8 * u(rng));
    x.col(3) = Vector3d(1.0, 1.5 * u(rng) + 0.5, 0.8 * u(rng));
    x = scale * (random_rotation(rng) * (x + 0.2 * shells::HingePositions::NullaryExpr([&] { return u(rng); })));
    const Eigen::MatrixXd H = shells::dihedral_hessian(x);
    const Eigen::MatrixXd H_fd = fd_jacobian<shells::HingePositions>(
        [](const shells::HingePositions& y) { return Eigen::VectorXd(shells::dihedral_gradient(y)); }, x, 1e-6 * scale);
    CHECK(rel_err(H, H_fd) < 1e-6);
  }
}

TEST_CASE("PSD projection clamps negative eigenvalues and keeps PSD matrices") {
  std::mt19937 rng(19);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  elements::Mat<12> A = elements::Mat<12>::NullaryExpr([&] { return u(rng); });
  A = 0.5 * (A + A.transpose()).eval();
  Eigen::SelfAdjointEigenSolver<elements::Mat<12>> before(A);
  REQUIRE(before.eigenvalues().minCoeff() < 0.0);
  elements::Mat<12> P = A;
  const double lowest = elements::project_psd(P);
  CHECK(lowest == doctest::Approx(before.eigenvalues().minCoeff()));
  Eigen::SelfAdjointEigenSolver<elements::Mat<12>> after(P);
  const auto expect = before.eigenvalues().cwiseMax(0.0).eval();
  CHECK((after.eigenvalues() - expect).cwiseAbs().maxCoeff() < 1e-12);
  elements::Mat<12> Q = P * P + elements::Mat<12>::Identity();  // positive definite: unchanged
  const elements::Mat<12> keep = Q;
  CHECK(elements::project_psd(Q) == 0.0);
  CHECK((Q - keep).cwiseAbs().maxCoeff() < 1e-12 * keep.cwiseAbs().maxCoeff());
}

TEST_CASE("elastic force terms: forces are minus the gradient and assembled Jacobians match finite differences") {
  std::mt19937 rng(20);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  System sys;
  const TetMesh box = kuhn_box(2, 1, 1, 2.0, 1.0, 1.0);
  for (const auto& p : box.x) sys.nodes().add(p, Vector3d::Zero(), 1.0);
  auto& tets = sys.add<solids::Tets>(solids::TetLaw::stable_neo_hookean);
  for (const auto& t : box.tets) {
    solids::TetPositions X;
    for (int a = 0; a < 4; ++a) X.col(a) = box.x[t[a]];
    tets.add(t, X, 1e3, 0.3);
  }
  // A shell on the top face: membrane triangles and their interior hinges.
  std::vector<std::array<Index, 3>> top;
  for (int j = 0; j < 1; ++j)
    for (int i = 0; i < 2; ++i) {
      const Index a = box.index(i, j, 1, 2, 1), b = box.index(i + 1, j, 1, 2, 1), c = box.index(i + 1, j + 1, 1, 2, 1),
                  d = box.index(i, j + 1, 1, 2, 1);
      top.push_back({a, b, c});
      top.push_back({a, c, d});
    }
  auto& membranes = sys.add<shells::Membranes>();
  for (const auto& t : top) {
    shells::TriPositions X;
    for (int a = 0; a < 3; ++a) X.col(a) = box.x[t[a]];
    membranes.add(t, X, 5e2, 0.3, 0.01);
  }
  std::vector<double> rest_x;
  for (const auto& p : box.x) rest_x.insert(rest_x.end(), {p.x(), p.y(), p.z()});
  auto& hinges = sys.add<shells::Hinges>();
  CHECK(hinges.add_interior_edges(top, rest_x, 10.0) == 3);
  for (Index i = 0; i < sys.nodes().size(); ++i)
    sys.nodes().set_position(i, sys.nodes().position(i) + 0.15 * Vector3d(u(rng), u(rng), u(rng)));
  JacobianOptions exact;
  const Eigen::MatrixXd J = assembled(sys, 1.0, 0.0, exact);
  const Eigen::MatrixXd J_fd = finite_difference(sys, false, 1e-6);
  CHECK(max_abs(J - J_fd) < 1e-6 * max_abs(J_fd));
  // Velocity-independent: ∂F/∂v = 0.
  CHECK(max_abs(assembled(sys, 0.0, 1.0, exact)) == 0.0);
  // With projection, -∂F/∂x is PSD.
  JacobianOptions projected;
  projected.project_element_hessians = true;
  const Eigen::MatrixXd K = -assembled(sys, 1.0, 0.0, projected);
  Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eig(K);
  CHECK(eig.eigenvalues().minCoeff() > -1e-10 * eig.eigenvalues().maxCoeff());
  // The product path equals the assembled matrix.
  std::vector<double> p(J.rows()), out(J.rows(), 0.0);
  for (auto& v : p) v = u(rng);
  JacobianRequest req;
  req.product_in = p;
  req.product_out = out;
  for (const auto& t : sys.terms()) t->add_jacobians(sys.nodes().state(), req);
  const Eigen::VectorXd expect = J * Eigen::Map<Eigen::VectorXd>(p.data(), J.rows());
  CHECK((Eigen::Map<Eigen::VectorXd>(out.data(), J.rows()) - expect).cwiseAbs().maxCoeff() < 1e-10 * expect.norm());
}

TEST_CASE("elastic force terms reject bad elements naming them, before changing anything") {
  System sys;
  for (int i = 0; i < 4; ++i) sys.nodes().add(Vector3d(i == 1, i == 2, i == 3), Vector3d::Zero(), 1.0);
  auto& tets = sys.add<solids::Tets>();
  solids::TetPositions flat;
  flat << 0, 1, 0, 1, 0, 0, 1, 1, 0, 0, 0, 0;
  CHECK_THROWS_WITH_AS(tets.add({0, 1, 2, 3}, flat, 1e3, 0.3), doctest::Contains("tets element 0: tetrahedron: degenerate"),
                       InputError);
  solids::TetPositions X;
  X << 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1;
  CHECK_THROWS_WITH_AS(tets.add({0, 1, 2, 3}, X, 1e3, 0.5), doctest::Contains("Poisson"), InputError);
  CHECK_THROWS_WITH_AS(tets.add({0, 1, 1, 3}, X, 1e3, 0.3), doctest::Contains("node 1 appears twice"), InputError);
  CHECK(tets.size() == 0);
  tets.add({0, 1, 2, 7}, X, 1e3, 0.3);
  CHECK_THROWS_WITH_AS(sys.refresh(), doctest::Contains("tets element 0 refers to node 7"), InputError);
  auto& hinges = sys.add<shells::Hinges>();
  CHECK_THROWS_AS(hinges.add({0, 1, 2, 3}, X, -1.0), InputError);
  const std::vector<std::array<Index, 3>> flipped{{0, 1, 2}, {1, 2, 3}};  // both run 1->2
  std::vector<double> rest{0, 0, 0, 1, 0, 0, 0, 1, 0, 1, 1, 0};
  CHECK_THROWS_WITH_AS(hinges.add_interior_edges(flipped, rest, 1.0), doctest::Contains("oriented inconsistently"),
                       InputError);
}

}  // namespace test_elastic_elements
