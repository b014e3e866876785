// Patch bending (shells/patch_element.hpp, patch_terms.hpp): derivatives against central
// differences on random and clamped patches, zero energy and force under rigid motions, the
// exact plate energy of any quadratic deflection on irregular meshes (the consistency the hinge
// model lacks), and the strip cantilever's convergence to Euler–Bernoulli at second order on
// meshes with either diagonal orientation and on one-row meshes.
#include <doctest/doctest.h>

#include <algorithm>
#include <cmath>
#include <functional>
#include <random>
#include <string>

#include "../../bench/elastic/shell_strip.hpp"
#include "elastic_helpers.hpp"
#include "helpers.hpp"
#include "sewn/physics/shells/patch_terms.hpp"
#include "sewn/physics/shells/shell_terms.hpp"

namespace test_elastic_shells {
namespace {

using sewn::physics::Index;
namespace shells = sewn::physics::shells;

// A flat triangle (0,0), (1,0), (0.3,0.9) with neighbours across its three edges, perturbed.
shells::PatchPositions<6> flat_patch(std::mt19937& rng, double noise) {
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  shells::PatchPositions<6> X;
  X.col(0) << 0, 0, 0;
  X.col(1) << 1, 0, 0;
  X.col(2) << 0.3, 0.9, 0;
  X.col(3) << 1.2, 0.8, 0;    // across edge 0 (corners 1, 2)
  X.col(4) << -0.6, 0.5, 0;   // across edge 1 (corners 2, 0)
  X.col(5) << 0.45, -0.8, 0;  // across edge 2 (corners 0, 1)
  for (int c = 0; c < 6; ++c) X.col(c) += noise * Eigen::Vector3d(u(rng), u(rng), 0.0);
  return X;
}

template <int N>
shells::PatchPositions<N> take(const shells::PatchPositions<6>& X, const std::array<int, N>& cols) {
  shells::PatchPositions<N> out;
  for (int c = 0; c < N; ++c) out.col(c) = X.col(cols[static_cast<std::size_t>(c)]);
  return out;
}

template <int N>
void check_patch(const shells::PatchPositions<N>& X, const std::array<std::uint8_t, N - 3>& edges,
                 const std::array<std::uint8_t, N - 3>& clamped, std::mt19937& rng, double amplitude = 0.3) {
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  const shells::PatchRest rest = shells::patch_rest<N>(X, edges, clamped, shells::plate_material(1e3, 0.3, 0.1));
  using P = shells::PatchPositions<N>;
  const auto E = [&](const P& x) { return shells::patch_energy<N>(x, rest); };
  const auto G = [&](const P& x) { return shells::patch_gradient<N>(x, rest); };
  const auto H = [&](const P& x) { return shells::patch_hessian<N>(x, rest); };
  // bent by up to `amplitude` per coordinate, then rotated and moved rigidly
  const P x = X + amplitude * P::NullaryExpr([&] { return u(rng); });
  sewn::physics::test::check_element<N>(E, G, H, x, 1e-6, 1e-5);
  // the line search's one-pass energy and gradient give what the two separate calls give
  sewn::physics::elements::Vec<3 * N> g;
  const double e = shells::patch_energy_gradient<N>(x, rest, g);
  CHECK(e == doctest::Approx(E(x)).epsilon(1e-14));
  CHECK((g - G(x)).cwiseAbs().maxCoeff() <= 1e-14 * G(x).cwiseAbs().maxCoeff());
  const Eigen::Matrix3d R = sewn::physics::test::random_rotation(rng);
  P moved = R * X;
  moved.colwise() += Eigen::Vector3d(u(rng), u(rng), u(rng));
  CHECK(std::abs(E(moved)) <= 1e-20);
  CHECK(G(moved).cwiseAbs().maxCoeff() <= 1e-12);
  CHECK(std::abs(E(R * x) - E(x)) <= 1e-10 * E(x));
}

TEST_CASE("patch bending: gradients and Hessians match finite differences, rigid motions cost nothing") {
  std::mt19937 rng(42);
  for (int trial = 0; trial < 10; ++trial) {
    const shells::PatchPositions<6> X = flat_patch(rng, 0.1);
    check_patch<6>(X, {0, 1, 2}, {0, 0, 0}, rng);
    check_patch<6>(X, {0, 1, 2}, {0, 1, 0}, rng);
    check_patch<5>(take<5>(X, {0, 1, 2, 4, 5}), {1, 2}, {0, 0}, rng);
    check_patch<5>(take<5>(X, {0, 1, 2, 3, 5}), {0, 2}, {1, 0}, rng);
    check_patch<4>(take<4>(X, {0, 1, 2, 5}), {2}, {0}, rng);
    check_patch<4>(take<4>(X, {0, 1, 2, 3}), {0}, {1}, rng);
    // nearly flat: every dihedral angle within ~1e-4 rad of its rest value
    check_patch<6>(X, {0, 1, 2}, {0, 0, 0}, rng, 1e-4);
    check_patch<5>(take<5>(X, {0, 1, 2, 3, 5}), {0, 2}, {1, 0}, rng, 1e-4);
  }
  // a curved rest patch (every rest angle nonzero): still zero energy at rest
  shells::PatchPositions<6> X = flat_patch(rng, 0.0);
  for (int c = 0; c < 6; ++c) X(2, c) = 0.4 * X(0, c) * X(0, c) - 0.2 * X(0, c) * X(1, c) + 0.3 * X(1, c) * X(1, c);
  check_patch<6>(X, {0, 1, 2}, {0, 0, 0}, rng);
}

TEST_CASE("patch bending: refuses degenerate patches by name") {
  const auto m = shells::plate_material(1e3, 0.3, 0.1);
  shells::PatchPositions<4> X;
  X << 0, 1, 0.5, 2, 0, 0, 0, 0, 0, 0, 0, 0;  // a flat (zero-area) triangle
  CHECK_THROWS_WITH_AS((void)shells::patch_rest<4>(X, {0}, {0}, m), doctest::Contains("degenerate rest triangle"),
                       sewn::physics::InputError);
  X << 0, 1, 0, 2, 0, 0, 1, -1, 0, 0, 0, 0;  // the neighbour across edge 0 on the edge's line
  CHECK_THROWS_WITH_AS((void)shells::patch_rest<4>(X, {0}, {0}, m), doctest::Contains("lies on the edge's line"),
                       sewn::physics::InputError);
  CHECK_THROWS_AS((void)shells::plate_material(1e3, 0.5, 0.1), sewn::physics::InputError);
}

// The plate energy density (D/2)[(1-ν) tr(K²) + ν (tr K)²] of curvature K.
double plate_density(const shells::PlateMaterial& m, const Eigen::Matrix2d& K) {
  return 0.5 * m.stiffness * ((1.0 - m.poisson) * (K * K).trace() + m.poisson * K.trace() * K.trace());
}

TEST_CASE("patch bending: every interior patch of an irregular mesh bends a quadratic with the plate's exact energy") {
  // jittered nodes, diagonals drawn at random: no two patches alike
  const auto s = sewn::shell_strip::strip_mesh(sewn::shell_strip::Mesh::jittered, 40);
  const shells::PlateMaterial m = shells::plate_material(1.0, 0.3, 1.0);
  const double eps = 1e-5;  // small slopes: the angles' nonlinearity is O(ε²) relative
  Eigen::Matrix2d K;
  K << 0.7, -0.4, -0.4, 1.3;
  sewn::physics::System sys;
  const Index n = static_cast<Index>(s.rest.size() / 3);
  for (Index i = 0; i < n; ++i) {
    const Eigen::Vector2d p(s.rest[3 * i], s.rest[3 * i + 1]);
    sys.nodes().add(Eigen::Vector3d(p.x(), p.y(), eps * (0.5 * p.dot(K * p) + 0.2 * p.x() - 0.1)), Eigen::Vector3d::Zero(), 1.0);
  }
  const std::vector<shells::PlateMaterial> mat(s.triangles.size(), m);
  const shells::PatchTerms terms = shells::add_patch_bending(sys, s.triangles, s.rest, mat);
  REQUIRE(terms.three != nullptr);
  REQUIRE(terms.three->size() > 200);
  for (Index e = 0; e < terms.three->size(); ++e) {
    const auto& tri = s.triangles[terms.triangle_of[2][e]];
    const auto at = [&](int c) { return Eigen::Vector2d(s.rest[3 * std::size_t{tri[static_cast<std::size_t>(c)]}],
                                                         s.rest[3 * std::size_t{tri[static_cast<std::size_t>(c)]} + 1]); };
    const Eigen::Vector2d u = at(1) - at(0), v = at(2) - at(0);
    const double area = 0.5 * std::abs(u.x() * v.y() - u.y() * v.x());
    const double exact = area * plate_density(m, eps * K);
    CHECK(terms.three->element_energy(e, terms.three->gather(sys.state(), e)) == doctest::Approx(exact).epsilon(1e-6));
  }
}

// The jittered strip of 20 columns, its nodes added to sys moved from rest by up to `amplitude`
// in x and y and 3 × that in z (bent and stretched).
sewn::shell_strip::Strip bent_strip(sewn::physics::System& sys, unsigned seed, double amplitude) {
  auto s = sewn::shell_strip::strip_mesh(sewn::shell_strip::Mesh::jittered, 20);
  const Index n = static_cast<Index>(s.rest.size() / 3);
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  for (Index i = 0; i < n; ++i) {
    const Eigen::Vector3d X(s.rest[3 * i], s.rest[3 * i + 1], s.rest[3 * i + 2]);
    sys.nodes().add(X + amplitude * Eigen::Vector3d(u(rng), u(rng), 3.0 * u(rng)), Eigen::Vector3d::Zero(), 1.0);
  }
  return s;
}

TEST_CASE("shell terms: add_forces_and_energy equals potential_energy and add_forces on a bent, stretched mesh") {
  sewn::physics::System sys;
  const auto s = bent_strip(sys, 7, 0.01);
  const Index n = sys.nodes().size();
  const std::vector<shells::PlateMaterial> mat(s.triangles.size(), shells::plate_material(1e6, 0.3, 0.01));
  const shells::PatchTerms patches = shells::add_patch_bending(sys, s.triangles, s.rest, mat);
  auto& membranes = sys.add<shells::Membranes>();
  for (const auto& tri : s.triangles) {
    shells::TriPositions X;
    for (int c = 0; c < 3; ++c)
      for (int r = 0; r < 3; ++r) X(r, c) = s.rest[3 * std::size_t{tri[static_cast<std::size_t>(c)]} + static_cast<std::size_t>(r)];
    (void)membranes.add(tri, X, 1e6, 0.3, 0.01);
  }
  REQUIRE(patches.three != nullptr);
  REQUIRE(patches.two != nullptr);
  const sewn::physics::StateView state = sys.state();
  for (const auto& term : sys.terms()) {
    std::vector<double> f_two(3 * std::size_t{n}, 0.0), f_one(3 * std::size_t{n}, 0.0);
    const double e_two = term->potential_energy(state);
    term->add_forces(state, f_two);
    const double e_one = term->add_forces_and_energy(state, f_one);
    CAPTURE(term->name());
    CHECK(e_two > 0.0);
    CHECK(e_one == doctest::Approx(e_two).epsilon(1e-13));
    double largest = 0.0, diff = 0.0;
    for (std::size_t k = 0; k < f_two.size(); ++k) {
      largest = std::max(largest, std::abs(f_two[k]));
      diff = std::max(diff, std::abs(f_one[k] - f_two[k]));
    }
    CHECK(largest > 0.0);
    CHECK(diff <= 1e-13 * largest);
  }
}

// -Σ_e H_e scattered by hand, each element's Hessian on its own (patch_hessian, no sharing).
template <int N>
void subtract_element_hessians(const shells::PatchBending<N>* term, const sewn::physics::StateView& s, Eigen::MatrixXd& out) {
  if (term == nullptr) return;
  for (Index e = 0; e < term->size(); ++e) {
    const auto H = term->element_hessian(e, term->gather(s, e));
    const auto& n = term->element_nodes(e);
    for (int a = 0; a < N; ++a)
      for (int b = 0; b < N; ++b)
        out.block<3, 3>(3 * Eigen::Index{n[static_cast<std::size_t>(a)]}, 3 * Eigen::Index{n[static_cast<std::size_t>(b)]}) -=
            H.template block<3, 3>(3 * a, 3 * b);
  }
}

TEST_CASE("patch bending: exact Jacobians assembled with each edge's angle derivatives shared equal the elements' own") {
  sewn::physics::System sys;
  const auto s = bent_strip(sys, 11, 0.02);
  const std::vector<shells::PlateMaterial> mat(s.triangles.size(), shells::plate_material(1e6, 0.3, 0.01));
  const shells::PatchTerms patches = shells::add_patch_bending(sys, s.triangles, s.rest, mat);
  REQUIRE(patches.three != nullptr);
  REQUIRE(patches.two != nullptr);
  const Eigen::MatrixXd J = sewn::physics::test::assembled(sys, 1.0, 0.0, sewn::physics::JacobianOptions{});
  Eigen::MatrixXd expect = Eigen::MatrixXd::Zero(J.rows(), J.cols());
  subtract_element_hessians(patches.one, sys.state(), expect);
  subtract_element_hessians(patches.two, sys.state(), expect);
  subtract_element_hessians(patches.three, sys.state(), expect);
  using sewn::physics::test::max_abs;
  REQUIRE(max_abs(expect) > 0.0);
  CHECK(max_abs(J - expect) <= 1e-12 * max_abs(expect));
  // and both are the forces' derivative
  const Eigen::MatrixXd J_fd = sewn::physics::test::finite_difference(sys, false, 1e-7);
  CHECK(max_abs(J - J_fd) <= 1e-5 * max_abs(J_fd));
  // a cut hands an element other nodes: the table of shared edges follows the topology
  const auto nodes = patches.three->element_nodes(0);
  auto moved = nodes;
  moved[0] = sys.nodes().add(sys.nodes().position(nodes[0]), Eigen::Vector3d::Zero(), 1.0);
  patches.three->set_element_nodes(0, moved);
  const Eigen::MatrixXd J_cut = sewn::physics::test::assembled(sys, 1.0, 0.0, sewn::physics::JacobianOptions{});
  Eigen::MatrixXd expect_cut = Eigen::MatrixXd::Zero(J_cut.rows(), J_cut.cols());
  subtract_element_hessians(patches.one, sys.state(), expect_cut);
  subtract_element_hessians(patches.two, sys.state(), expect_cut);
  subtract_element_hessians(patches.three, sys.state(), expect_cut);
  CHECK(max_abs(J_cut - expect_cut) <= 1e-12 * max_abs(expect_cut));
}

TEST_CASE("patch bending: the strip cantilever converges to Euler-Bernoulli at second order on structured meshes") {
  // the hinge model's limit on these meshes is 20 % (square) to 100 % (row) too soft
  using sewn::shell_strip::Mesh;
  const double exact = sewn::shell_strip::euler_bernoulli_m();
  for (Mesh mesh : {Mesh::square, Mesh::flipped, Mesh::row}) {
    const std::string name = sewn::shell_strip::mesh_name(mesh);
    CAPTURE(name);
    std::vector<double> err;
    for (int nx : {10, 20, 40}) {
      const auto r = sewn::shell_strip::solve(mesh, sewn::shell_strip::Bending::patch, nx);
      err.push_back(std::abs(r.tip_m - exact) / exact);
    }
    for (std::size_t k = 1; k < err.size(); ++k) {
      const double order = std::log2(err[k - 1] / err[k]);
      CAPTURE(order);
      CHECK(order > 1.8);
      CHECK(order < 2.2);
    }
  }
}

}  // namespace
}  // namespace test_elastic_shells
