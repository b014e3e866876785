// Morley bending (shells/morley_element.hpp, morley_terms.hpp): derivatives in positions and
// edge angles against central differences for every edge kind, zero energy and force under
// rigid motions, the plate's exact energy for a quadratic deflection on every triangle of an
// irregular mesh (which also checks that the two triangles of an edge agree on its
// mid-normal), and the strip cantilever's convergence to Euler–Bernoulli on irregular meshes.
#include <doctest/doctest.h>

#include <algorithm>
#include <cmath>
#include <functional>
#include <random>
#include <string>
#include <vector>

#include "../../bench/elastic/shell_strip.hpp"
#include "elastic_helpers.hpp"
#include "sewn/physics/integrate/newton_euler.hpp"
#include "sewn/physics/shells/morley_terms.hpp"

namespace test_elastic_morley {
namespace {

using sewn::physics::Index;
namespace shells = sewn::physics::shells;
using Dofs = Eigen::Matrix<double, 21, 1>;

// Errors of successive halvings of the cell fall at an observed order of 2 (1.7 to 2.4).
void check_second_order(const std::vector<double>& err) {
  for (std::size_t k = 1; k < err.size(); ++k) {
    const double order = std::log2(err[k - 1] / err[k]);
    CAPTURE(order);
    CHECK(order > 1.7);
    CHECK(order < 2.4);
  }
}

shells::MorleyPositions positions_of(const Dofs& q) { return Eigen::Map<const shells::MorleyPositions>(q.data()); }
Eigen::Vector3d angles_of(const Dofs& q) { return q.tail<3>(); }

// A triangle (0,0), (1,0), (0.3,0.9) with a neighbour across each edge, in-plane noise added.
shells::MorleyPositions flat_stencil(std::mt19937& rng, double noise) {
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  shells::MorleyPositions X;
  X << 0, 1, 0.3, 1.2, -0.6, 0.45,  //
      0, 0, 0.9, 0.8, 0.5, -0.8,    //
      0, 0, 0, 0, 0, 0;
  for (int c = 0; c < 6; ++c) X.col(c) += noise * Eigen::Vector3d(u(rng), u(rng), 0.0);
  return X;
}

void check_stencil(const shells::MorleyPositions& X, const std::array<shells::MorleyEdge, 3>& kind, std::mt19937& rng,
                   double amplitude = 0.3) {
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  const shells::MorleyRest rest = shells::morley_rest(X, kind, shells::plate_material(1e3, 0.3, 0.1));
  const std::function<double(const Dofs&)> E = [&](const Dofs& q) {
    return shells::morley_energy(positions_of(q), angles_of(q), rest);
  };
  const std::function<Eigen::VectorXd(const Dofs&)> G = [&](const Dofs& q) {
    return Eigen::VectorXd(shells::morley_gradient(positions_of(q), angles_of(q), rest));
  };
  Dofs q = Dofs::Zero();  // the edge angles start at 0 (rest), then turned below
  q.head<18>() = Eigen::Map<const Eigen::Matrix<double, 18, 1>>(X.data());
  for (int k = 0; k < 21; ++k) q[k] += amplitude * u(rng);  // bent, and every mid-normal turned
  const Eigen::VectorXd g = G(q);
  const Eigen::MatrixXd H = shells::morley_hessian(positions_of(q), angles_of(q), rest);
  const double g_err = sewn::physics::test::rel_err(g, sewn::physics::test::fd_gradient<Dofs>(E, q, 1e-6));
  const double h_err = sewn::physics::test::rel_err(H, sewn::physics::test::fd_jacobian<Dofs>(G, q, 1e-6));
  CAPTURE(g_err);
  CAPTURE(h_err);
  CHECK(g_err < 1e-6);
  CHECK(h_err < 1e-5);
  // per stencil, zero net force and torque: the angles are measured from the triangles, so a
  // rotation of the positions alone is rigid (the position part of the gradient only)
  const auto [f, t] = sewn::physics::test::net_force_torque<6>(positions_of(q), g.head<18>());
  const double scale = g.cwiseAbs().maxCoeff() * (1.0 + positions_of(q).cwiseAbs().maxCoeff());
  CHECK(f.norm() <= 1e-12 * scale);
  CHECK(t.norm() <= 1e-12 * scale);
  // rigid motions with the angles at rest: no energy, no force, no torque on the angles
  const Eigen::Matrix3d R = sewn::physics::test::random_rotation(rng);
  shells::MorleyPositions moved = R * X;
  moved.colwise() += Eigen::Vector3d(u(rng), u(rng), u(rng));
  CHECK(std::abs(shells::morley_energy(moved, Eigen::Vector3d::Zero(), rest)) <= 1e-20);
  CHECK(shells::morley_gradient(moved, Eigen::Vector3d::Zero(), rest).cwiseAbs().maxCoeff() <= 1e-12);
  // and a bent state keeps its energy when moved
  const shells::MorleyPositions x = positions_of(q);
  CHECK(shells::morley_energy(R * x, angles_of(q), rest) == doctest::Approx(E(q)).epsilon(1e-10));
}

TEST_CASE("Morley bending: gradients and Hessians in positions and edge angles match finite differences") {
  using K = shells::MorleyEdge;
  std::mt19937 rng(7);
  for (int trial = 0; trial < 6; ++trial) {
    const shells::MorleyPositions X = flat_stencil(rng, 0.1);
    check_stencil(X, {K::own, K::own, K::own}, rng);
    check_stencil(X, {K::other, K::own, K::clamp}, rng);
    check_stencil(X, {K::other, K::other, K::other}, rng);
    check_stencil(X, {K::clamp, K::clamp, K::own}, rng);
    // nearly flat: every hinge within 1e-4 rad of flat, mid-normals barely turned
    check_stencil(X, {K::own, K::own, K::own}, rng, 1e-4);
    check_stencil(X, {K::other, K::own, K::clamp}, rng, 1e-4);
  }
  // a curved rest shape: zero energy at rest all the same
  shells::MorleyPositions X = flat_stencil(rng, 0.0);
  for (int c = 0; c < 6; ++c) X(2, c) = 0.4 * X(0, c) * X(0, c) - 0.2 * X(0, c) * X(1, c) + 0.3 * X(1, c) * X(1, c);
  check_stencil(X, {K::other, K::own, K::clamp}, rng);
  const shells::MorleyRest rest = shells::morley_rest(X, {K::other, K::other, K::other}, shells::plate_material(1e3, 0.3, 0.1));
  CHECK(std::abs(shells::morley_energy(X, Eigen::Vector3d::Zero(), rest)) <= 1e-20);
}

TEST_CASE("Morley bending: refuses degenerate triangles and hinges by name") {
  using K = shells::MorleyEdge;
  const auto m = shells::plate_material(1e3, 0.3, 0.1);
  shells::MorleyPositions X = shells::MorleyPositions::Zero();
  X.row(0) << 0, 1, 0.5, 0, 0, 0;  // corners on a line
  CHECK_THROWS_WITH_AS((void)shells::morley_rest(X, {K::own, K::own, K::own}, m), doctest::Contains("degenerate rest triangle"),
                       sewn::physics::InputError);
  X.row(0) << 0, 1, 0, 2, 0, 0;  // the node across edge 0 on the edge's line
  X.row(1) << 0, 0, 1, -1, 0, 0;
  CHECK_THROWS_WITH_AS((void)shells::morley_rest(X, {K::other, K::own, K::own}, m), doctest::Contains("across edge 0"),
                       sewn::physics::InputError);
  CHECK_THROWS_WITH_AS((void)shells::morley_rest(X, {K::own, K::own, K::own}, shells::PlateMaterial{-1.0, 0.3}),
                       doctest::Contains("plate stiffness"), sewn::physics::InputError);
}

double plate_density(const shells::PlateMaterial& m, const Eigen::Matrix2d& K) {
  return 0.5 * m.stiffness * ((1.0 - m.poisson) * (K * K).trace() + m.poisson * K.trace() * K.trace());
}

TEST_CASE("Morley bending: every triangle of an irregular mesh bends a quadratic with the plate's exact energy") {
  // Deflection w = ε(½pᵀKp + bᵀp + c), each edge's mid-normal set to w's slope at its midpoint
  // through the owner triangle's angle: the other triangle reads the same mid-normal through
  // its hinge, so its energy is exact only if both sides agree.
  for (auto mesh : {sewn::shell_strip::Mesh::jittered, sewn::shell_strip::Mesh::offset}) {
    const auto s = sewn::shell_strip::strip_mesh(mesh, 20);
    const shells::PlateMaterial m = shells::plate_material(1.0, 0.3, 1.0);
    const double eps = 1e-5;
    Eigen::Matrix2d K;
    K << 0.7, -0.4, -0.4, 1.3;
    const Eigen::Vector2d b(0.2, -0.1);
    auto w = [&](const Eigen::Vector2d& p) { return eps * (0.5 * p.dot(K * p) + b.dot(p) - 0.1); };
    auto dw = [&](const Eigen::Vector2d& p) -> Eigen::Vector2d { return eps * (K * p + b); };
    sewn::physics::System sys;
    const Index n = static_cast<Index>(s.rest.size() / 3);
    auto rest2 = [&](Index v) { return Eigen::Vector2d(s.rest[3 * std::size_t{v}], s.rest[3 * std::size_t{v} + 1]); };
    for (Index i = 0; i < n; ++i) sys.nodes().add(Eigen::Vector3d(rest2(i).x(), rest2(i).y(), w(rest2(i))), Eigen::Vector3d::Zero(), 1.0);
    const std::vector<shells::PlateMaterial> mat(s.triangles.size(), m);
    const shells::MorleyTerms terms = shells::add_morley_bending(sys, s.triangles, s.rest, mat);
    REQUIRE(terms.term != nullptr);
    REQUIRE(terms.term->size() == s.triangles.size());
    for (Index e = 0; e < terms.term->size(); ++e) {
      const auto& el = terms.term->element(e);
      for (int i = 0; i < 3; ++i) {
        if (el.rest.kind[static_cast<std::size_t>(i)] != shells::MorleyEdge::own) continue;
        const Eigen::Vector2d p0 = rest2(el.nodes[static_cast<std::size_t>(i)]);
        const Eigen::Vector2d p1 = rest2(el.nodes[static_cast<std::size_t>((i + 1) % 3)]);
        const Eigen::Vector2d p2 = rest2(el.nodes[static_cast<std::size_t>((i + 2) % 3)]);
        Eigen::Vector2d out(p2.y() - p1.y(), p1.x() - p2.x());  // outward for a counter-clockwise triangle
        out.normalize();
        // the linear interpolant's slope along `out`: (w(p2) - w(p1)) along the edge is the
        // tangential part, the normal part from the height of corner i
        Eigen::Matrix2d A;
        A << (p1 - p0).transpose(), (p2 - p0).transpose();
        const Eigen::Vector2d grad_l = A.inverse() * Eigen::Vector2d(w(p1) - w(p0), w(p2) - w(p0));
        sys.angles().values()[el.angle[static_cast<std::size_t>(i)]] = std::atan((dw(0.5 * (p1 + p2)) - grad_l).dot(out));
      }
    }
    const auto state = sys.state();
    for (Index e = 0; e < terms.term->size(); ++e) {
      const auto& tri = s.triangles[terms.triangle_of[e]];
      const Eigen::Vector2d u = rest2(tri[1]) - rest2(tri[0]), v = rest2(tri[2]) - rest2(tri[0]);
      const double exact = 0.5 * std::abs(u.x() * v.y() - u.y() * v.x()) * plate_density(m, eps * K);
      const auto& el = terms.term->element(e);
      shells::MorleyPositions x = shells::MorleyPositions::Zero();
      Eigen::Vector3d psi = Eigen::Vector3d::Zero();
      for (std::size_t c = 0; c < 6; ++c)
        if (el.nodes[c] != sewn::physics::invalid_index) x.col(static_cast<Eigen::Index>(c)) = sys.nodes().position(el.nodes[c]);
      for (std::size_t i = 0; i < 3; ++i)
        if (el.angle[i] != sewn::physics::invalid_index) psi[static_cast<Eigen::Index>(i)] = state.angles[el.angle[i]];
      CHECK(shells::morley_energy(x, psi, el.rest) == doctest::Approx(exact).epsilon(1e-4));
    }
  }
}

TEST_CASE("Morley bending: the strip cantilever converges to Euler-Bernoulli at second order on irregular meshes") {
  // patch bending stays 4-20 % too soft on the jittered and random-diagonal meshes without a
  // trend (docs/elastic.md); Morley's tip error falls 4x per halving on every mesh
  using sewn::shell_strip::Mesh;
  const double exact = sewn::shell_strip::euler_bernoulli_m();
  for (Mesh mesh : {Mesh::square, Mesh::jittered, Mesh::diagonals, Mesh::offset}) {
    const std::string name = sewn::shell_strip::mesh_name(mesh);
    CAPTURE(name);
    std::vector<double> err;
    for (int nx : {10, 20, 40}) {
      const auto r = sewn::shell_strip::solve(mesh, sewn::shell_strip::Bending::morley, nx);
      err.push_back(std::abs(r.tip_m - exact) / exact);
    }
    check_second_order(err);
  }
}

TEST_CASE("Morley bending: a one-row strip converges at second order in the cell's length and its height") {
  // A one-row strip of fixed width stalls at 0.5 % (docs/elastic.md): Morley's tip error is a
  // second-order term in each cell dimension, (a² + c²/2)/L² on these meshes (cell length a,
  // height c), and a fixed-width row never shortens c. Not a boundary or clamp defect: the row
  // converges once its width shrinks with the cells, and at fixed nx the part from the height
  // falls 4x per halving of the width.
  using sewn::shell_strip::Mesh;
  using sewn::shell_strip::Shape;
  const double exact = sewn::shell_strip::euler_bernoulli_m();
  auto error = [&](int nx, double width) {
    const auto r = sewn::shell_strip::solve(Mesh::row, sewn::shell_strip::Bending::morley, nx, Shape{width, 1});
    return std::abs(r.tip_m - exact) / exact;
  };
  SUBCASE("triangles of aspect 4 (width 4 cells), nx = 10, 20, 40") {
    std::vector<double> err;
    for (int nx : {10, 20, 40}) err.push_back(error(nx, 4.0 / nx));
    check_second_order(err);
  }
  SUBCASE("nx = 40, width 0.2, 0.1, 0.05: the differences fall at second order in the height") {
    const double e1 = error(40, 0.2), e2 = error(40, 0.1), e3 = error(40, 0.05);
    const double order = std::log2((e1 - e2) / (e2 - e3));
    CAPTURE(order);
    CHECK(order > 1.7);
    CHECK(order < 2.4);
  }
}

TEST_CASE("Morley bending: an edge angle's lever arm is its triangles' height, and Newton's step test weighs the angle by it") {
  // A unit square cut along its diagonal: boundary edges 1 m from the opposite corner, the
  // diagonal √2/2 m from both. Newton weighing a mid-normal's step in rad as if in m kept
  // shell scenes iterating after their positions had converged (docs/elastic.md).
  const std::vector<std::array<Index, 3>> tris{{0, 1, 2}, {0, 2, 3}};
  const std::vector<double> rest{0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 1, 0};
  const std::vector<shells::PlateMaterial> mat(2, shells::plate_material(1e6, 0.3, 0.01));
  sewn::physics::System sys;
  for (Index i = 0; i < 4; ++i)
    sys.nodes().add(Eigen::Vector3d(rest[3 * i], rest[3 * i + 1], i == 3 ? 0.1 : 0.0), Eigen::Vector3d::Zero(), 1.0);
  for (Index i = 0; i < 4; ++i) sys.nodes().fix(i);  // bent and held: only the mid-normals move
  const shells::MorleyTerms terms = shells::add_morley_bending(sys, tris, rest, mat);
  REQUIRE(terms.angles == 5);
  std::vector<double> levers(sys.angles().lengths().begin(), sys.angles().lengths().end());
  std::sort(levers.begin(), levers.end());
  CHECK(levers[0] == doctest::Approx(std::sqrt(0.5)).epsilon(1e-14));
  for (std::size_t a = 1; a < levers.size(); ++a) CHECK(levers[a] == doctest::Approx(1.0).epsilon(1e-14));
  CHECK_THROWS_AS(sys.angles().set_length(0, 0.0), sewn::physics::InputError);
  CHECK_THROWS_AS(sys.angles().set_length(5, 1.0), sewn::physics::InputError);

  // One Newton iteration (the energy is quadratic in the angles: the step is exact), refused
  // for its tolerance: the reported |p|∞/h doubles when every lever arm does.
  sewn::physics::integrate::NewtonEulerOptions opt;
  opt.solver = sewn::physics::integrate::LinearSolver::ldlt;
  opt.max_iterations = 1;
  opt.velocity_tolerance = 1e-30;
  auto step_velocity = [&] {
    sewn::physics::integrate::NewtonEuler newton(opt);
    try {
      (void)newton.step(sys, 0.01);
    } catch (const sewn::physics::integrate::NewtonError& e) {
      return e.report().step_velocity;
    }
    return -1.0;
  };
  const double v1 = step_velocity();
  for (Index a = 0; a < terms.angles; ++a)
    sys.angles().set_length(terms.first_angle + a, 2.0 * sys.angles().lengths()[terms.first_angle + a]);
  const double v2 = step_velocity();
  CHECK(v1 > 0.0);
  CHECK(v2 == doctest::Approx(2.0 * v1).epsilon(1e-10));
}

}  // namespace
}  // namespace test_elastic_morley
