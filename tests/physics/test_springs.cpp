// Spring term: forces against the energy, Jacobians against finite differences of the
// forces (generic, nearly collinear, axis-aligned, nearly zero-length), the vector loop
// against a plain reference, invariances, the SPD options, and incremental edits.
#include <doctest/doctest.h>

#include <cmath>
#include <random>

#include <Eigen/Eigenvalues>

#include "helpers.hpp"

namespace test_springs {

using namespace sewn::physics;
using namespace sewn::physics::test;
using Eigen::Vector3d;

namespace {

// Straightforward per-spring forces, written independently of springs.cpp's loop.
Eigen::VectorXd reference_forces(const System& sys, const Springs& sp) {
  const NodeTable& nd = sys.nodes();
  Eigen::VectorXd f = Eigen::VectorXd::Zero(3 * Eigen::Index{nd.size()});
  for (Index s = 0; s < sp.size(); ++s) {
    if (!sp.is_alive(s)) continue;
    const Index i = sp.node_i(s), j = sp.node_j(s);
    const Vector3d dx = nd.position(j) - nd.position(i), dv = nd.velocity(j) - nd.velocity(i);
    const double d = dx.norm(), k = sp.stiffness(s), l = sp.rest_length(s);
    const Vector3d U = dx / d;
    Vector3d fi = k * (d - l) * U;
    if (sp.damping() == SpringDamping::viscous) fi += sp.viscosity(s) * dv.dot(U) * U;
    if (sp.damping() == SpringDamping::stiffness_proportional) {
      const Eigen::Matrix3d Q = Eigen::Matrix3d::Identity() - U * U.transpose();
      fi += sp.rayleigh_beta() * k * (U * U.transpose() + std::max(0.0, 1 - l / d) * Q) * dv;
    }
    f.segment<3>(3 * i) += fi;
    f.segment<3>(3 * j) -= fi;
  }
  return f;
}

// Σ ½ k (|xj − xi| − l)² over the live springs, one by one.
double reference_energy(const System& sys, const Springs& sp) {
  const NodeTable& nd = sys.nodes();
  double e = 0;
  for (Index s = 0; s < sp.size(); ++s) {
    if (!sp.is_alive(s)) continue;
    const double t = (nd.position(sp.node_j(s)) - nd.position(sp.node_i(s))).norm() - sp.rest_length(s);
    e += 0.5 * sp.stiffness(s) * t * t;
  }
  return e;
}

// n nodes at random in the unit cube with random velocities, and m springs between random
// distinct nodes with rest lengths 0.5..1.5 × current (so both stretched and compressed).
Springs& random_scene(System& sys, std::mt19937& rng, int n, int m, SpringDamping damping) {
  std::uniform_real_distribution<double> u(0.0, 1.0);
  for (int i = 0; i < n; ++i)
    sys.nodes().add({u(rng), u(rng), u(rng)}, {u(rng) - 0.5, u(rng) - 0.5, u(rng) - 0.5}, 0.5 + u(rng));
  Springs& sp = sys.add<Springs>(damping, 0.03);
  std::uniform_int_distribution<int> pick(0, n - 1);
  for (int s = 0; s < m; ++s) {
    int i = pick(rng), j = pick(rng);
    while (j == i) j = pick(rng);
    const double d = (sys.nodes().position(j) - sys.nodes().position(i)).norm();
    sp.add(i, j, 10 + 90 * u(rng), d * (0.5 + u(rng)), SpringKind::edge, 0.5 + u(rng));
  }
  return sp;
}

// delta: position step; velocity steps are 1e-6 (the forces are linear in the velocities, so
// only round-off limits that step, and it must not be tiny).
void check_jacobians(System& sys, double delta, double tol) {
  const JacobianOptions exact{false, false};
  const Eigen::MatrixXd Jx = assembled(sys, 1, 0, exact);
  const Eigen::MatrixXd Jx_fd = finite_difference(sys, false, delta);
  CHECK(max_abs(Jx - Jx_fd) <= tol * max_abs(Jx));
  const Eigen::MatrixXd Jv = assembled(sys, 0, 1, exact);
  const Eigen::MatrixXd Jv_fd = finite_difference(sys, true, 1e-6);
  if (max_abs(Jv_fd) > 0) CHECK(max_abs(Jv - Jv_fd) <= tol * max_abs(Jv_fd));
  else CHECK(max_abs(Jv) == 0.0);
}

double energy_at(System& sys) { return sys.potential_energy(); }

}  // namespace

TEST_CASE("spring forces are minus the energy gradient (random seeded configurations)") {
  for (unsigned seed : {1u, 2u, 3u}) {
    System sys;
    std::mt19937 rng(seed);
    random_scene(sys, rng, 10, 23, SpringDamping::none);  // 23: vector loop plus a scalar tail
    const Eigen::VectorXd f = forces(sys);
    auto x = sys.nodes().x();
    const double h = 1e-6;
    Eigen::VectorXd g(f.size());
    for (Eigen::Index c = 0; c < f.size(); ++c) {
      const double keep = x[c];
      x[c] = keep + h;
      const double ep = energy_at(sys);
      x[c] = keep - h;
      const double em = energy_at(sys);
      x[c] = keep;
      g[c] = (ep - em) / (2 * h);
    }
    CHECK((f + g).cwiseAbs().maxCoeff() <= 1e-7 * f.cwiseAbs().maxCoeff());
  }
}

TEST_CASE("the vector force loop matches a plain per-spring reference for every damping model") {
  for (SpringDamping model : {SpringDamping::none, SpringDamping::viscous, SpringDamping::stiffness_proportional}) {
    System sys;
    std::mt19937 rng(7);
    const Springs& sp = random_scene(sys, rng, 15, 41, model);
    const Eigen::VectorXd f = forces(sys);
    const Eigen::VectorXd r = reference_forces(sys, sp);
    CHECK((f - r).cwiseAbs().maxCoeff() <= 1e-13 * r.cwiseAbs().maxCoeff());
  }
}

namespace {

// Nodes of an nx×ny×nz lattice (jittered, random velocities) numbered x fastest, with the
// springs a hexahedral grid has (edges and the 4 diagonals of each cell), so that most of them
// come in runs of consecutive nodes. A third of the runs are reversed (j < i) and a few single
// springs too: the chunks must take each spring from its lower node, whichever end is i.
Springs& lattice_scene(System& sys, std::mt19937& rng, int nx, int ny, int nz, SpringDamping damping) {
  std::uniform_real_distribution<double> u(0.0, 1.0);
  const auto id = [&](int x, int y, int z) { return static_cast<Index>(x + nx * (y + ny * z)); };
  for (int z = 0; z < nz; ++z)
    for (int y = 0; y < ny; ++y)
      for (int x = 0; x < nx; ++x)
        sys.nodes().add({x + 0.2 * u(rng), y + 0.2 * u(rng), z + 0.2 * u(rng)}, {u(rng) - 0.5, u(rng) - 0.5, u(rng) - 0.5},
                        0.5 + u(rng));
  Springs& sp = sys.add<Springs>(damping, 0.03);
  const auto spring = [&](Index i, Index j, bool reversed) {
    const double d = (sys.nodes().position(j) - sys.nodes().position(i)).norm();
    if (reversed != (u(rng) < 0.03)) std::swap(i, j);
    sp.add(i, j, 10 + 90 * u(rng), d * (0.5 + u(rng)), SpringKind::edge, 0.5 + u(rng));
  };
  const int offsets[][2][3] = {{{0, 0, 0}, {1, 0, 0}}, {{0, 0, 0}, {0, 1, 0}}, {{0, 0, 0}, {0, 0, 1}},
                               {{0, 0, 0}, {1, 1, 1}}, {{1, 0, 0}, {0, 1, 1}}, {{0, 1, 0}, {1, 0, 1}},
                               {{0, 0, 1}, {1, 1, 0}}};
  for (int f = 0; f < 7; ++f) {
    const auto& o = offsets[f];
    for (int z = 0; z + 1 < nz; ++z)
      for (int y = 0; y + 1 < ny; ++y)
        for (int x = 0; x + 1 < nx; ++x)
          spring(id(x + o[0][0], y + o[0][1], z + o[0][2]), id(x + o[1][0], y + o[1][1], z + o[1][2]), (f + z) % 3 == 0);
  }
  return sp;
}

}  // namespace

TEST_CASE("springs in runs take the chunked loop, which matches the reference through random edits") {
  for (SpringDamping model : {SpringDamping::none, SpringDamping::viscous, SpringDamping::stiffness_proportional}) {
    CAPTURE(int(model));
    System sys;
    std::mt19937 rng(11);
    Springs& sp = lattice_scene(sys, rng, 11, 7, 5, model);  // 385 nodes: not a multiple of 8
    // the energy takes the chunks too: its sum only regroups the reference's
    const auto energy_matches = [&] {
      const double r = reference_energy(sys, sp);
      return r > 0 && std::abs(sp.potential_energy(sys.state()) - r) <= 1e-13 * r;
    };
    Eigen::VectorXd f = forces(sys);
    CHECK(sp.num_in_runs() >= sp.num_alive() / 2);
    CHECK(max_abs(f - reference_forces(sys, sp)) <= 1e-13 * max_abs(f));
    CHECK(energy_matches());
    // set_forces (the system's first term) must agree with add_forces.
    sys.compute_forces();
    const auto fs = sys.nodes().f();
    CHECK(max_abs(Eigen::VectorXd(Eigen::Map<const Eigen::VectorXd>(fs.data(), f.size())) - f) == 0.0);

    const Index n = sys.nodes().size();
    std::uniform_int_distribution<Index> node(0, n - 1);
    std::uniform_real_distribution<double> u(0.0, 1.0);
    const auto live_spring = [&] {
      std::uniform_int_distribution<Index> pick(0, sp.size() - 1);
      Index s = pick(rng);
      while (!sp.is_alive(s)) s = pick(rng);
      return s;
    };
    // Re-attaching springs to their own nodes sends them to the rest list one by one, until
    // the list is long enough for a rebuild, which puts every one back in its chunk.
    const Index initial = sp.num_in_runs();
    bool came_back = false;
    for (int step = 0; step < 400 && !came_back; ++step) {
      const Index before = sp.num_in_runs();
      const Index s = live_spring();
      sp.set_endpoints(s, sp.node_i(s), sp.node_j(s));
      f = forces(sys);
      REQUIRE(max_abs(f - reference_forces(sys, sp)) <= 1e-13 * max_abs(f));
      REQUIRE(energy_matches());
      came_back = sp.num_in_runs() > before;
    }
    CHECK(came_back);
    CHECK(sp.num_in_runs() == initial);
    for (int step = 0; step < 600; ++step) {
      switch (step % 6) {
        case 0: sp.remove(live_spring()); break;
        case 1: {
          Index i = node(rng), j = node(rng);
          while (j == i) j = node(rng);
          sp.add(i, j, 50, 0.9 * (sys.nodes().position(j) - sys.nodes().position(i)).norm(), SpringKind::other, 2);
          break;
        }
        case 2: {
          const Index s = live_spring();
          Index j = node(rng);
          while (j == sp.node_i(s)) j = node(rng);
          sp.set_endpoints(s, sp.node_i(s), j);
          break;
        }
        case 3: sp.set_stiffness(live_spring(), 5 + 50 * u(rng)); break;
        case 4: sp.set_rest_length(live_spring(), 0.5 + u(rng)); break;
        default: sp.set_viscosity(live_spring(), u(rng)); break;
      }
      f = forces(sys);
      REQUIRE(max_abs(f - reference_forces(sys, sp)) <= 1e-13 * max_abs(f));
      REQUIRE(energy_matches());
    }
    sp.set_paper_viscosity(sys.nodes().masses());
    f = forces(sys);
    CHECK(max_abs(f - reference_forces(sys, sp)) <= 1e-13 * max_abs(f));
    sp.compact();
    f = forces(sys);
    CHECK(sp.num_in_runs() > 0);
    CHECK(max_abs(f - reference_forces(sys, sp)) <= 1e-13 * max_abs(f));
    CHECK(energy_matches());
  }
}

TEST_CASE("on a lattice whose springs are all in runs, forces are joined block by block and match the reference") {
  // No rest springs: each node's forces are written out as soon as the chunks pass it, while
  // later chunks are still accumulating (a 7×6×5 box has far more than one block of chunks).
  for (SpringDamping model : {SpringDamping::none, SpringDamping::viscous, SpringDamping::stiffness_proportional}) {
    System sys;
    BoxLatticeSpec spec;
    spec.nx = 7;
    spec.ny = 6;
    spec.nz = 5;
    spec.E = 1e3;
    spec.damping = model;
    spec.rayleigh_beta = 0.05;
    const BoxLattice lat = build_box_lattice(sys, spec);
    Springs& sp = *lat.springs;
    std::mt19937 rng(21);
    std::uniform_real_distribution<double> u(-0.1, 0.1);
    for (Index i = 0; i < sys.nodes().size(); ++i) {
      sys.nodes().set_position(i, sys.nodes().position(i) + Eigen::Vector3d(u(rng), u(rng), u(rng)));
      sys.nodes().set_velocity(i, Eigen::Vector3d(u(rng), u(rng), u(rng)));
    }
    const Eigen::VectorXd f = forces(sys);
    REQUIRE(sp.num_in_runs() > 8 * 64);
    CHECK(max_abs(f - reference_forces(sys, sp)) <= 1e-13 * max_abs(f));
    // Then one spring re-attached to low nodes: the rest list holds the join front back.
    sp.set_endpoints(sp.size() - 1, 0, 1);
    const Eigen::VectorXd g = forces(sys);
    CHECK(max_abs(g - reference_forces(sys, sp)) <= 1e-13 * max_abs(g));
  }
}

TEST_CASE("springs given with their ends in either order still form runs") {
  // As the tetrahedral builder gives them: orientation follows the element, not the numbering.
  System sys;
  BoxLatticeSpec spec;
  spec.nx = 6;
  spec.ny = 5;
  spec.nz = 4;
  spec.damping = SpringDamping::viscous;
  const BoxLattice lat = build_box_lattice(sys, spec);
  Springs& sp = *lat.springs;
  (void)forces(sys);
  const Index all_in_runs = sp.num_in_runs();
  std::mt19937 rng(8);
  for (Index s = 0; s < sp.size(); ++s)
    if (rng() % 2 == 0) sp.set_endpoints(s, sp.node_j(s), sp.node_i(s));
  for (Index i = 0; i < sys.nodes().size(); ++i)
    sys.nodes().set_velocity(i, Eigen::Vector3d(0.01 * (i % 7), -0.02 * (i % 3), 0.005 * (i % 5)));
  const Eigen::VectorXd f = forces(sys);  // half the springs re-attached: the plan is rebuilt
  CHECK(sp.num_in_runs() == all_in_runs);
  CHECK(max_abs(f - reference_forces(sys, sp)) <= 1e-13 * max_abs(f));
}

TEST_CASE("the chunked loop passes a NaN position on to the forces") {
  System sys;
  std::mt19937 rng(5);
  Springs& sp = lattice_scene(sys, rng, 9, 4, 3, SpringDamping::viscous);
  (void)forces(sys);
  REQUIRE(sp.num_in_runs() > 0);
  const Index bad = 13;  // an interior node
  sys.nodes().x()[3 * bad + 1] = std::nan("");
  const Eigen::VectorXd f = forces(sys);
  CHECK(std::isnan(f[3 * bad + 1]));
  CHECK_FALSE(std::isnan(f[3 * (bad + 2 * 9 + 6)]));  // a node sharing no spring with it
}

TEST_CASE("spring Jacobians match finite differences of the forces") {
  SUBCASE("random configurations, every damping model") {
    for (SpringDamping model : {SpringDamping::none, SpringDamping::viscous, SpringDamping::stiffness_proportional}) {
      for (unsigned seed : {11u, 12u}) {
        System sys;
        std::mt19937 rng(seed);
        random_scene(sys, rng, 8, 17, model);
        if (model == SpringDamping::stiffness_proportional) {
          // K_s is held constant within a step (its position derivative is not assembled),
          // so ∂F/∂x is exact only where the Rayleigh force vanishes: at zero velocity.
          auto v = sys.nodes().v();
          std::fill(v.begin(), v.end(), 0.0);
        }
        check_jacobians(sys, 1e-6, 1e-6);
      }
    }
  }
  SUBCASE("nearly collinear chain") {
    System sys;
    for (int i = 0; i < 6; ++i) sys.nodes().add({0.3 * i, 1e-7 * ((i % 2) ? 1 : -1), 2e-8 * i}, {0.1 * i, -0.2, 0.05 * i}, 1.0);
    Springs& sp = sys.add<Springs>(SpringDamping::viscous);
    for (int i = 0; i + 1 < 6; ++i) sp.add(i, i + 1, 100.0, 0.25 + 0.02 * i, SpringKind::edge, 2.0);
    for (int i = 0; i + 2 < 6; ++i) sp.add(i, i + 2, 50.0, 0.65, SpringKind::edge, 1.0);
    check_jacobians(sys, 1e-9, 1e-6);
  }
  SUBCASE("axis-aligned springs (where the seed's W form divides 0 by 0)") {
    System sys;
    sys.nodes().add({0, 0, 0}, {0.1, 0.2, 0.3}, 1.0);
    sys.nodes().add({1.2, 0, 0}, {-0.3, 0.1, 0.0}, 2.0);
    sys.nodes().add({0, 0.8, 0}, {0.0, -0.1, 0.4}, 1.5);
    sys.nodes().add({0, 0, 1.1}, {0.2, 0.2, -0.2}, 1.0);
    sys.nodes().add({1.2, 0.8, 0}, {0.0, 0.0, 0.1}, 1.0);
    Springs& sp = sys.add<Springs>(SpringDamping::viscous);
    sp.add(0, 1, 100, 1.0, SpringKind::edge, 3);
    sp.add(0, 2, 80, 1.0, SpringKind::edge, 2);
    sp.add(0, 3, 60, 1.0, SpringKind::edge, 1);
    sp.add(1, 4, 70, 0.5, SpringKind::edge, 2);
    sp.add(2, 4, 90, 1.5, SpringKind::edge, 2);
    check_jacobians(sys, 1e-7, 1e-6);
  }
  SUBCASE("nearly zero-length springs (d = 1e-3 l and 1e-6 l)") {
    for (double ratio : {1e-3, 1e-6}) {
      System sys;
      const double l = 0.1, d = ratio * l;
      sys.nodes().add({0, 0, 0}, {0.01, 0, 0}, 1.0);
      sys.nodes().add(Vector3d(1, 2, 2).normalized() * d, {0, 0.01, 0}, 1.0);
      sys.nodes().add({0.05, 0.07, 0.0}, {0, 0, 0.01}, 1.0);
      sys.nodes().add({0.0, 0.06, 0.08}, {0, 0, 0}, 1.0);
      Springs& sp = sys.add<Springs>(SpringDamping::viscous);
      sp.add(0, 1, 100, l, SpringKind::edge, 1.0);
      sp.add(1, 2, 100, 0.1, SpringKind::edge, 1.0);
      sp.add(2, 3, 100, 0.1, SpringKind::edge, 1.0);
      sp.add(0, 3, 100, 0.1, SpringKind::edge, 1.0);
      check_jacobians(sys, 1e-4 * d, 1e-6);
    }
  }
}

TEST_CASE("degenerate springs exert no force and add no Jacobian, never NaN") {
  System sys;
  sys.nodes().add({1, 1, 1}, {1, 0, 0}, 1.0);
  sys.nodes().add({1, 1, 1}, {0, 1, 0}, 1.0);               // coincident with node 0
  sys.nodes().add({1, 1, 1 + 1e-12}, {0, 0, 1}, 1.0);       // 1e-11 of the rest length away
  sys.nodes().add({2, 1, 1}, {0, 0, 0}, 1.0);
  Springs& sp = sys.add<Springs>(SpringDamping::viscous);
  sp.add(0, 1, 100, 0.1, SpringKind::edge, 1.0);
  sp.add(0, 2, 100, 0.1, SpringKind::edge, 1.0);
  sp.add(1, 2, 100, 0.1, SpringKind::edge, 1.0);
  sp.add(2, 3, 100, 1.0, SpringKind::edge, 1.0);  // a normal one, 4 springs: the vector loop
  const Eigen::VectorXd f = forces(sys);
  CHECK(f.allFinite());
  const Vector3d dx = sys.nodes().position(3) - sys.nodes().position(2);
  const Vector3d dv = sys.nodes().velocity(3) - sys.nodes().velocity(2);
  const Vector3d U = dx.normalized();
  const Vector3d f23 = 100 * (dx.norm() - 1.0) * U + 1.0 * dv.dot(U) * U;
  CHECK((f.segment<3>(0)).norm() == doctest::Approx(0.0));
  CHECK((f.segment<3>(3)).norm() == doctest::Approx(0.0));
  CHECK((f.segment<3>(6) - f23).norm() <= 1e-12);
  const Eigen::MatrixXd J = assembled(sys, 1, 1, JacobianOptions{false, false});
  CHECK(J.allFinite());
  CHECK(J.block(0, 0, 6, 6).cwiseAbs().maxCoeff() == 0.0);
}

TEST_CASE("rigid motions produce no spring force") {
  System sys;
  std::mt19937 rng(5);
  Springs& sp = random_scene(sys, rng, 9, 20, SpringDamping::viscous);
  for (Index s = 0; s < sp.size(); ++s)  // rest state = current state
    sp.set_rest_length(s, (sys.nodes().position(sp.node_j(s)) - sys.nodes().position(sp.node_i(s))).norm());
  const Eigen::Matrix3d R = Eigen::AngleAxisd(0.7, Vector3d(1, 2, 3).normalized()).toRotationMatrix();
  const Vector3d omega(0.3, -1.2, 2.0), c(5, -3, 2);
  double scale = 0;
  for (Index s = 0; s < sp.size(); ++s) scale = std::max(scale, sp.stiffness(s) * sp.rest_length(s));
  for (Index i = 0; i < sys.nodes().size(); ++i) {
    const Vector3d p = R * sys.nodes().position(i) + c;
    sys.nodes().set_position(i, p);
    sys.nodes().set_velocity(i, omega.cross(p) + Vector3d(1, 2, 3));
  }
  CHECK(forces(sys).cwiseAbs().maxCoeff() <= 1e-12 * scale);
}

TEST_CASE("solver simplifications: clamped compression is PSD, dropped viscous terms are symmetric") {
  System sys;
  std::mt19937 rng(21);
  random_scene(sys, rng, 8, 20, SpringDamping::viscous);  // rest lengths up to 1.5 d: compressed springs
  const Eigen::MatrixXd exact = assembled(sys, 1, 0, JacobianOptions{false, false});
  CHECK(max_abs(exact - exact.transpose()) > 1e-6 * max_abs(exact));  // ∂Fv/∂P is not symmetric
  const Eigen::MatrixXd Jn = assembled(sys, 1, 0, JacobianOptions{true, false});
  CHECK(max_abs(Jn - Jn.transpose()) <= 1e-14 * max_abs(Jn));
  const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> unclamped(-Jn);
  CHECK(unclamped.eigenvalues().minCoeff() < -1e-6 * max_abs(Jn));  // compression: indefinite
  const Eigen::MatrixXd Jc = assembled(sys, 1, 0, JacobianOptions{true, true});
  const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> clamped(-Jc);
  CHECK(clamped.eigenvalues().minCoeff() >= -1e-12 * max_abs(Jc));
  CHECK_FALSE(sys.terms()[0]->jacobian_symmetric(JacobianOptions{false, true}));
  CHECK(sys.terms()[0]->jacobian_symmetric(JacobianOptions{true, false}));
}

TEST_CASE("the ∂F/∂x product uses the same Jacobian as the matrix") {
  System sys;
  std::mt19937 rng(8);
  random_scene(sys, rng, 7, 15, SpringDamping::viscous);
  const JacobianOptions opt{true, true};
  const Eigen::MatrixXd J = assembled(sys, 1, 0, opt);
  Eigen::VectorXd p = Eigen::VectorXd::Random(J.cols());
  std::vector<double> out(static_cast<std::size_t>(J.rows()), 0.0);
  JacobianRequest r;
  r.product_in = std::span<const double>(p.data(), static_cast<std::size_t>(p.size()));
  r.product_out = out;
  r.options = opt;
  sys.add_jacobians(r);
  std::vector<double> expect(out.size());
  sys.matrix().multiply(r.product_in, expect);  // the matrix still holds J from assembled()
  double err = 0, scale = 0;
  for (std::size_t k = 0; k < out.size(); ++k) {
    err = std::max(err, std::abs(out[k] - expect[k]));
    scale = std::max(scale, std::abs(expect[k]));
  }
  CHECK(scale > 0);
  CHECK(err <= 1e-12 * scale);
}

TEST_CASE("springs support incremental edits with stable indices") {
  System sys;
  for (int i = 0; i < 5; ++i) sys.nodes().add({double(i), 0, 0}, Vector3d::Zero(), 1.0);
  Springs& sp = sys.add<Springs>();
  const Index a = sp.add(0, 1, 10, 1);
  const Index b = sp.add(1, 2, 20, 1, SpringKind::diagonal);
  const Index c = sp.add(2, 3, 30, 1);
  CHECK(sys.refresh());
  CHECK_FALSE(sys.refresh());
  CHECK(sp.kind(b) == SpringKind::diagonal);
  sp.remove(b);
  CHECK_FALSE(sp.is_alive(b));
  CHECK(sp.num_alive() == 2);
  CHECK_THROWS_AS((void)sp.stiffness(b), InputError);
  const Index d = sp.add(3, 4, 40, 1);
  CHECK(d == b);  // slot reuse
  sp.move_endpoint(d, 4, 0);
  CHECK(sp.node_i(d) == 3);
  CHECK(sp.node_j(d) == 0);
  CHECK_THROWS_WITH_AS(sp.move_endpoint(d, 2, 1), doctest::Contains("not node 2"), InputError);
  sp.set_stiffness(a, 11);
  sp.set_rest_length(c, 0.9);
  CHECK(sp.stiffness(a) == 11);
  CHECK(sys.refresh());  // endpoints moved: new pattern
  CHECK(sys.matrix().find(3, 0) != invalid_index);
  CHECK(sys.matrix().find(1, 2) == invalid_index);
  sp.remove(a);
  const auto map = sp.compact();
  CHECK(map[a] == invalid_index);
  CHECK(map[d] == 0);  // d reused slot 1, which precedes c's slot 2
  CHECK(map[c] == 1);
  CHECK(sp.size() == 2);
  CHECK(sp.node_i(0) == 3);
}

TEST_CASE("bad spring input is refused with a message naming the spring") {
  System sys;
  sys.nodes().add({0, 0, 0}, Vector3d::Zero(), 1.0);
  sys.nodes().add({1, 0, 0}, Vector3d::Zero(), 1.0);
  Springs& sp = sys.add<Springs>();
  CHECK_THROWS_WITH_AS(sp.add(0, 0, 1, 1), doctest::Contains("to itself"), InputError);
  CHECK_THROWS_WITH_AS(sp.add(0, 1, -1, 1), doctest::Contains("stiffness of spring 0"), InputError);
  CHECK_THROWS_WITH_AS(sp.add(0, 1, 1, std::nan("")), doctest::Contains("rest length"), InputError);
  CHECK_THROWS_AS(Springs(SpringDamping::stiffness_proportional, -1.0), InputError);
  sp.add(0, 1, 1, 1);
  sp.add(1, 7, 1, 1);
  CHECK_THROWS_WITH_AS(sys.refresh(), doctest::Contains("spring 1 refers to node 7"), InputError);
  CHECK_THROWS_AS((void)paper_viscosity(1, 0, 1), InputError);
  CHECK(paper_viscosity(8, 1, 3) == doctest::Approx(8.0));
}

namespace test_springs_fast_jacobian {
namespace {

// cx·Jx + cv·Jv and Jx·p assembled spring by spring from the 3×3 formulas of springs.hpp
// (Jx = k(UUᵀ + c(I − UUᵀ)), Jv per damping model), independently of spring_jacobian.cpp.
struct Reference {
  Eigen::MatrixXd matrix;
  Eigen::VectorXd product;
};

Reference reference_jacobian(const System& sys, const Springs& sp, double cx, double cv, bool clamp,
                             const Eigen::VectorXd& p) {
  const NodeTable& nd = sys.nodes();
  const Eigen::Index n3 = 3 * Eigen::Index{nd.size()};
  Reference r{Eigen::MatrixXd::Zero(n3, n3), Eigen::VectorXd::Zero(n3)};
  const Eigen::Matrix3d I = Eigen::Matrix3d::Identity();
  for (Index s = 0; s < sp.size(); ++s) {
    if (!sp.is_alive(s)) continue;
    const Index i = sp.node_i(s), j = sp.node_j(s);
    const Vector3d dx = nd.position(j) - nd.position(i);
    const double d = dx.norm(), k = sp.stiffness(s), l = sp.rest_length(s);
    if (!(d > 1e-9 * l)) continue;  // no direction: no Jacobian
    const Vector3d U = dx / d;
    const Eigen::Matrix3d UU = U * U.transpose(), Q = I - UU;
    const double stretch = 1 - l / d;
    const Eigen::Matrix3d Jx = k * (UU + (clamp ? std::max(0.0, stretch) : stretch) * Q);
    Eigen::Matrix3d Jv = Eigen::Matrix3d::Zero();
    if (sp.damping() == SpringDamping::viscous) Jv = sp.viscosity(s) * UU;
    if (sp.damping() == SpringDamping::stiffness_proportional)
      Jv = sp.rayleigh_beta() * k * (UU + std::max(0.0, stretch) * Q);
    const Eigen::Matrix3d B = cx * Jx + cv * Jv;
    for (const auto& [a, b, sign] : {std::tuple{i, j, 1.0}, std::tuple{j, i, 1.0}, std::tuple{i, i, -1.0}, std::tuple{j, j, -1.0}})
      r.matrix.block<3, 3>(3 * Eigen::Index{a}, 3 * Eigen::Index{b}) += sign * B;
    const Vector3d q = Jx * (p.segment<3>(3 * Eigen::Index{j}) - p.segment<3>(3 * Eigen::Index{i}));
    r.product.segment<3>(3 * Eigen::Index{i}) += q;
    r.product.segment<3>(3 * Eigen::Index{j}) -= q;
  }
  return r;
}

}  // namespace

TEST_CASE("the symmetric spring Jacobian (a·I + b·UUᵀ per spring) equals the 3×3 formulas to round-off") {
  for (SpringDamping model : {SpringDamping::none, SpringDamping::viscous, SpringDamping::stiffness_proportional})
    for (bool clamp : {true, false}) {
      CAPTURE(static_cast<int>(model));
      CAPTURE(clamp);
      System sys;
      std::mt19937 rng(31);
      // 300 springs: more than one chunk of the one-thread assembly
      Springs& sp = random_scene(sys, rng, 40, 300, model);
      sp.remove(7);  // a tombstone
      sys.nodes().set_position(sp.node_j(11), sys.nodes().position(sp.node_i(11)));  // no direction
      const double cx = -2.5e-5, cv = -4e-3;
      const JacobianOptions opt{true, clamp};
      REQUIRE(sp.jacobian_symmetric(opt));
      const Eigen::MatrixXd A = assembled(sys, cx, cv, opt);
      Eigen::VectorXd p = Eigen::VectorXd::Random(A.cols());
      std::vector<double> out(static_cast<std::size_t>(A.rows()), 0.0);
      JacobianRequest r;
      r.product_in = std::span<const double>(p.data(), static_cast<std::size_t>(p.size()));
      r.product_out = out;
      r.options = opt;
      sys.add_jacobians(r);
      const Reference ref = reference_jacobian(sys, sp, cx, cv, clamp, p);
      CHECK(max_abs(ref.matrix) > 0);
      CHECK(max_abs(A - ref.matrix) <= 1e-14 * max_abs(ref.matrix));
      const Eigen::VectorXd q = Eigen::Map<const Eigen::VectorXd>(out.data(), static_cast<Eigen::Index>(out.size()));
      CHECK(max_abs(q - ref.product) <= 1e-14 * max_abs(ref.product));
      CHECK(A.allFinite());
    }
}

}  // namespace test_springs_fast_jacobian

}  // namespace test_springs
