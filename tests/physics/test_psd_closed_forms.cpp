// The closed-form PSD Hessians Newton uses instead of an eigendecomposition per element
// (StencilTerm::element_hessian_psd): the membrane's with its compressive principal stresses
// clamped in the geometric term, the hinge's Gauss-Newton part. Each is checked against the
// exact Hessian (itself checked against finite differences in test_elastic_elements.cpp)
// where they must agree, against central differences of the gradient there, and for being
// PSD and differing from the exact Hessian only by the term it is said to drop.
#include <doctest/doctest.h>

#include <cmath>
#include <random>

#include <Eigen/Eigenvalues>

#include "elastic_helpers.hpp"
#include "sewn/physics/elements/element_math.hpp"
#include "sewn/physics/rods/stencils.hpp"
#include "sewn/physics/shells/patch_element.hpp"
#include "sewn/physics/shells/shell_terms.hpp"
#include "sewn/physics/solids/tet_element.hpp"

namespace test_psd_closed_forms {
namespace {

namespace ph = sewn::physics;
namespace sh = sewn::physics::shells;

double lowest_eigenvalue(const Eigen::MatrixXd& H) {
  return Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd>(H).eigenvalues().minCoeff();
}

// Principal stresses of the membrane at x, from its gradient's definition S = 2μE + λ tr(E) I.
Eigen::Vector2d principal_stresses(const sh::TriPositions& x, const sh::TriRest& rest, const sh::MembraneMaterial& m) {
  const Eigen::Matrix2d E = sh::membrane_strain(x, rest);
  const Eigen::Matrix2d S = 2.0 * m.mu * E + m.lambda_ps * E.trace() * Eigen::Matrix2d::Identity();
  return Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d>(S).eigenvalues();
}

sh::TriPositions rest_triangle(std::mt19937& rng) {
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  sh::TriPositions X;
  X << 0, 1, 0, 0, 0, 1, 0, 0, 0;
  return X + 0.2 * sh::TriPositions::NullaryExpr([&] { return u(rng); });
}

}  // namespace

TEST_CASE("membrane PSD Hessian: the exact Hessian under stretch, PSD under compression, off by the clamped stress only") {
  std::mt19937 rng(161);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  const auto mat = sh::membrane_material(2.0, 0.3, 0.05);
  int stretched = 0, compressed = 0;
  for (int trial = 0; trial < 40; ++trial) {
    CAPTURE(trial);
    const sh::TriPositions X = rest_triangle(rng);
    const sh::TriRest rest = sh::tri_rest(X);
    // Half the trials stretch the triangle by 1.3 (both principal stresses > 0), half squash
    // it to 0.7 (some or all < 0), each with a random rotation and a small random distortion.
    const double scale = trial % 2 == 0 ? 1.3 : 0.7;
    const sh::TriPositions x = ph::test::random_rotation(rng) * (scale * X) +
                               0.03 * sh::TriPositions::NullaryExpr([&] { return u(rng); });
    const Eigen::Vector2d sigma = principal_stresses(x, rest, mat);
    const sh::Mat9 H = sh::membrane_hessian(x, rest, mat);
    const sh::Mat9 P = sh::membrane_hessian_psd(x, rest, mat);
    const double size = H.cwiseAbs().maxCoeff();
    CHECK((P - P.transpose()).cwiseAbs().maxCoeff() <= 1e-14 * size);
    CHECK(lowest_eigenvalue(P) >= -1e-12 * size);
    if (sigma.minCoeff() >= 0.0) {
      ++stretched;
      CHECK((P - H).cwiseAbs().maxCoeff() <= 1e-13 * size);
      // and so it is the derivative of the gradient
      const auto grad = [&](const sh::TriPositions& y) { return Eigen::VectorXd(sh::membrane_gradient(y, rest, mat)); };
      CHECK(ph::test::rel_err(P, ph::test::fd_jacobian<sh::TriPositions>(grad, x, 1e-6)) < 1e-6);
      continue;
    }
    ++compressed;
    // Dropping the negative part of S from dF·S removes ((G s)(G s)ᵀ)⊗I₃ per negative σ
    // (G the constant node-to-F map), a PSD matrix of rank 3 each: P - H is PSD with
    // rank 3 × (number of negative principal stresses).
    const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> diff(Eigen::MatrixXd(P - H));
    CHECK(diff.eigenvalues().minCoeff() >= -1e-12 * size);
    int rank = 0;
    for (int k = 0; k < 9; ++k) rank += diff.eigenvalues()[k] > 1e-10 * size ? 1 : 0;
    CHECK(rank == 3 * ((sigma[0] < 0.0 ? 1 : 0) + (sigma[1] < 0.0 ? 1 : 0)));
    // The exact Hessian is indefinite here: the clamp is doing something.
    CHECK(lowest_eigenvalue(H) < -1e-8 * size);
  }
  CHECK(stretched >= 10);
  CHECK(compressed >= 10);
}

TEST_CASE("hinge Gauss-Newton Hessian: rank one and PSD, the exact Hessian at the rest angle, off by the curvature term") {
  std::mt19937 rng(162);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  const double kb = sh::hinge_stiffness(1e3, 0.3, 0.01);
  sh::HingePositions X;
  X.col(0) = Eigen::Vector3d(-1.0, 0.4, 0.3);
  X.col(1) = Eigen::Vector3d(0, 0, 0);
  X.col(2) = Eigen::Vector3d(0, 1, 0);
  X.col(3) = Eigen::Vector3d(1.0, 0.6, 0.2);
  const sh::HingeRest rest = sh::hinge_rest(X);
  const auto grad = [&](const sh::HingePositions& y) { return Eigen::VectorXd(sh::hinge_gradient(y, rest, kb)); };
  for (int trial = 0; trial < 10; ++trial) {
    CAPTURE(trial);
    // At the rest angle (a rigid motion of the rest hinge) the curvature term vanishes.
    const sh::HingePositions at_rest = (ph::test::random_rotation(rng) * X).colwise() + Eigen::Vector3d(u(rng), u(rng), u(rng));
    const sh::Mat12 G0 = sh::hinge_hessian_gauss_newton(at_rest, rest, kb);
    const double size0 = G0.cwiseAbs().maxCoeff();
    CHECK((G0 - sh::hinge_hessian(at_rest, rest, kb)).cwiseAbs().maxCoeff() <= 1e-10 * size0);
    CHECK(ph::test::rel_err(G0, ph::test::fd_jacobian<sh::HingePositions>(grad, at_rest, 1e-6)) < 1e-6);
    // Bent away from rest: PSD of rank one, the exact Hessian minus 2 k w (θ - θ̄) ∇²θ.
    const sh::HingePositions x = at_rest + 0.2 * sh::HingePositions::NullaryExpr([&] { return u(rng); });
    const sh::Mat12 G = sh::hinge_hessian_gauss_newton(x, rest, kb);
    const double size = G.cwiseAbs().maxCoeff();
    const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eig(Eigen::MatrixXd{G});
    CHECK(eig.eigenvalues().minCoeff() >= -1e-12 * size);
    CHECK(eig.eigenvalues()[10] <= 1e-12 * size);
    const double d = sh::wrap_angle(sh::dihedral_angle(x) - rest.theta);
    const sh::Mat12 curvature = 2.0 * kb * rest.weight * d * sh::dihedral_hessian(x);
    CHECK((sh::hinge_hessian(x, rest, kb) - G - curvature).cwiseAbs().maxCoeff() <= 1e-10 * size);
    CHECK(curvature.cwiseAbs().maxCoeff() > 1e-3 * size);
  }
}

TEST_CASE("patch bending Gauss-Newton Hessian: PSD, the exact Hessian at rest, off by the curvature terms") {
  std::mt19937 rng(163);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  using P6 = sh::PatchPositions<6>;
  // A slightly curved patch: a triangle with a neighbour across each edge, lifted off the plane.
  P6 X;
  X << 0, 1, 0.3, 1.2, -0.6, 0.45,  //
      0, 0, 0.9, 0.8, 0.5, -0.8,    //
      0, 0.05, -0.02, 0.1, 0.07, -0.04;
  const sh::PatchRest rest = sh::patch_rest<6>(X, {0, 1, 2}, {0, 0, 0}, sh::plate_material(1e3, 0.3, 0.1));
  const auto grad = [&](const P6& y) { return Eigen::VectorXd(sh::patch_gradient<6>(y, rest)); };
  for (int trial = 0; trial < 10; ++trial) {
    CAPTURE(trial);
    const P6 at_rest = (ph::test::random_rotation(rng) * X).colwise() + Eigen::Vector3d(u(rng), u(rng), u(rng));
    const auto G0 = sh::patch_hessian_gauss_newton<6>(at_rest, rest);
    const double size0 = G0.cwiseAbs().maxCoeff();
    CHECK((G0 - sh::patch_hessian<6>(at_rest, rest)).cwiseAbs().maxCoeff() <= 1e-10 * size0);
    CHECK(ph::test::rel_err(G0, ph::test::fd_jacobian<P6>(grad, at_rest, 1e-6)) < 1e-6);
    const P6 x = at_rest + 0.2 * P6::NullaryExpr([&] { return u(rng); });
    const auto G = sh::patch_hessian_gauss_newton<6>(x, rest);
    const double size = G.cwiseAbs().maxCoeff();
    const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eig(Eigen::MatrixXd{G});
    CHECK(eig.eigenvalues().minCoeff() >= -1e-12 * size);
    CHECK(eig.eigenvalues()[14] <= 1e-12 * size);  // rank ≤ 3: one row of J per edge
    // The exact Hessian less the Gauss-Newton part is the curvature terms, which vanish with
    // the bending: their size relative to JᵀSJ falls with the amplitude of the bend.
    const auto gap = [&](double amplitude) {
      const P6 y = at_rest + amplitude * (x - at_rest);
      return (sh::patch_hessian<6>(y, rest) - sh::patch_hessian_gauss_newton<6>(y, rest)).cwiseAbs().maxCoeff() /
             sh::patch_hessian_gauss_newton<6>(y, rest).cwiseAbs().maxCoeff();
    };
    CHECK(gap(1.0) > 1e-4);
    CHECK(gap(1e-3) < 2e-2 * gap(1.0));
  }
}

TEST_CASE("tet PSD tangent: neo-Hookean's closed-form eigensystem gives the nearest PSD tangent, StVK's clamp is exact in tension") {
  std::mt19937 rng(164);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  namespace so = sewn::physics::solids;
  const so::Lame lame = so::lame_from_young(1e4, 0.4);
  int clamped[2] = {0, 0}, kept[2] = {0, 0};
  for (int trial = 0; trial < 60; ++trial) {
    CAPTURE(trial);
    // Stretched, squashed, sheared, slightly stretched (3 %: neo-Hookean's tangent is PSD
    // there, at a rigid motion its twist eigenvalues are 0) and (one in six) inverted.
    const double scale = std::array<double, 3>{1.3, 0.6, 1.03}[trial % 3];
    const double noise = trial % 3 == 2 ? 0.005 : 0.3;
    Eigen::Matrix3d F = scale * ph::test::random_rotation(rng) + noise * Eigen::Matrix3d::NullaryExpr([&] { return u(rng); });
    if (trial % 6 == 5) F.col(0) = -F.col(0);
    for (const so::TetLaw law : {so::TetLaw::stable_neo_hookean, so::TetLaw::stvk}) {
      const int l = law == so::TetLaw::stvk ? 1 : 0;
      CAPTURE(l);
      const ph::elements::Mat<9> D = so::piola_derivative(law, F, lame);
      const ph::elements::Mat<9> P = so::piola_derivative_psd(law, F, lame);
      const double size = D.cwiseAbs().maxCoeff();
      CHECK((P - P.transpose()).cwiseAbs().maxCoeff() <= 1e-12 * size);
      CHECK(lowest_eigenvalue(P) >= -1e-12 * size);
      if (law == so::TetLaw::stable_neo_hookean) {
        // the nearest PSD tangent: the same as clamping the 9×9's eigenvalues numerically,
        // and D itself where D is PSD
        Eigen::MatrixXd projected = D;
        const bool psd = ph::elements::project_psd(projected) == 0.0;
        ++(psd ? kept : clamped)[l];
        CHECK((P - projected).cwiseAbs().maxCoeff() <= 1e-10 * size);
        if (psd) CHECK((P - D).cwiseAbs().maxCoeff() <= 1e-12 * size);
        continue;
      }
      // StVK: D itself wherever all three principal stresses are ≥ 0; elsewhere the
      // compressive stresses dropped from the geometric term only add stiffness
      const Eigen::Matrix3d E = 0.5 * (F.transpose() * F - Eigen::Matrix3d::Identity());
      const Eigen::Matrix3d S = 2.0 * lame.mu * E + lame.lambda * E.trace() * Eigen::Matrix3d::Identity();
      const bool tension = Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d>(S).eigenvalues().minCoeff() >= 0.0;
      ++(tension ? kept : clamped)[l];
      if (tension) CHECK((P - D).cwiseAbs().maxCoeff() <= 1e-12 * size);
      else CHECK(lowest_eigenvalue(P - D) >= -1e-12 * size);
    }
  }
  for (int l = 0; l < 2; ++l) {
    CAPTURE(l);
    CHECK(kept[l] >= 5);
    CHECK(clamped[l] >= 5);
  }
  // Assembled over a tetrahedron: PSD, and the exact Hessian (hence the derivative of the
  // gradient) where that is PSD: at a small uniform stretch.
  so::TetPositions X;
  X << 0, 1, 0, 0.1, 0, 0.1, 1, 0.2, 0, 0, 0.1, 1;
  const so::TetRest rest = so::tet_rest(X);
  for (const so::TetLaw law : {so::TetLaw::stable_neo_hookean, so::TetLaw::stvk}) {
    const so::TetPositions stretched = 1.05 * X;
    const so::Mat12 P = so::tet_hessian_psd(law, stretched, rest, lame);
    REQUIRE(lowest_eigenvalue(so::tet_hessian(law, stretched, rest, lame)) >= -1e-12 * P.cwiseAbs().maxCoeff());
    const auto grad = [&](const so::TetPositions& y) { return Eigen::VectorXd(so::tet_gradient(law, y, rest, lame)); };
    CHECK(ph::test::rel_err(P, ph::test::fd_jacobian<so::TetPositions>(grad, stretched, 1e-7)) < 1e-6);
    const so::TetPositions squashed = 0.5 * X + 0.1 * so::TetPositions::NullaryExpr([&] { return u(rng); });
    const so::Mat12 Q = so::tet_hessian_psd(law, squashed, rest, lame);
    CHECK(lowest_eigenvalue(Q) >= -1e-12 * Q.cwiseAbs().maxCoeff());
    CHECK(lowest_eigenvalue(so::tet_hessian(law, squashed, rest, lame)) < 0.0);
  }
}

TEST_CASE("rod stretch PSD Hessian: the eigen-projected one in closed form, stretched or compressed") {
  std::mt19937 rng(165);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  namespace ro = sewn::physics::rods;
  for (int trial = 0; trial < 20; ++trial) {
    CAPTURE(trial);
    const Eigen::Vector3d x0(u(rng), u(rng), u(rng)), x1(u(rng), u(rng), u(rng));
    const double rest = (x1 - x0).norm() * (trial % 2 == 0 ? 0.8 : 1.25);  // stretched, compressed
    const ro::StretchEval exact = ro::stretch(x0, x1, 3.0, rest, true);
    Eigen::MatrixXd projected = exact.hessian;
    ph::elements::project_psd(projected);
    const Eigen::Matrix<double, 6, 6> P = ro::stretch_hessian_psd(x0, x1, 3.0, rest);
    CHECK((P - projected).cwiseAbs().maxCoeff() <= 1e-12 * exact.hessian.cwiseAbs().maxCoeff());
    if (trial % 2 == 0) CHECK((P - exact.hessian).cwiseAbs().maxCoeff() <= 1e-14 * exact.hessian.cwiseAbs().maxCoeff());
    else CHECK((P - exact.hessian).cwiseAbs().maxCoeff() > 1e-3 * exact.hessian.cwiseAbs().maxCoeff());
  }
}

}  // namespace test_psd_closed_forms
