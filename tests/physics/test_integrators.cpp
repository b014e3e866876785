// Integrators and numerical health: the stable-step bound against PHYSICS_NOTES §1.6, the
// refusal above it, bounded runs below it, blow-up detection, conservation laws, implicit
// Euler's exact energy decay on a linear oscillator, filtering of fixed axes, damping
// models, CG failure reporting and NaN injection.
#include <doctest/doctest.h>

#include <algorithm>
#include <cmath>
#include <random>
#include <span>
#include <vector>

#include <Eigen/Dense>

#include "helpers.hpp"

namespace test_integrators {

using namespace sewn::physics;
using namespace sewn::physics::test;
using doctest::Approx;
using Eigen::Vector3d;

namespace {

BoxLattice cube_lattice(System& sys, Index n, double a, double E, double nu, double rho,
                        SpringDamping damping = SpringDamping::none) {
  BoxLatticeSpec s;
  s.nx = s.ny = s.nz = n;
  s.lx = s.ly = s.lz = a;
  s.E = E;
  s.nu = nu;
  s.rho = rho;
  s.damping = damping;
  return build_box_lattice(sys, s);
}

void perturb(System& sys, double dx, double dv, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  for (Index i = 0; i < sys.nodes().size(); ++i) {
    if (sys.nodes().fixed(i) == all_axes) continue;
    sys.nodes().set_position(i, sys.nodes().position(i) + dx * Vector3d(u(rng), u(rng), u(rng)));
    Vector3d v = dv * Vector3d(u(rng), u(rng), u(rng));
    for (int a = 0; a < 3; ++a)
      if ((sys.nodes().fixed(i) >> a) & 1) v[a] = 0;
    sys.nodes().set_velocity(i, v);
  }
}

Vector3d momentum(const System& sys) {
  Vector3d p = Vector3d::Zero();
  for (Index i = 0; i < sys.nodes().size(); ++i) p += sys.nodes().mass(i) * sys.nodes().velocity(i);
  return p;
}

Vector3d angular_momentum(const System& sys) {
  Vector3d L = Vector3d::Zero();
  for (Index i = 0; i < sys.nodes().size(); ++i)
    L += sys.nodes().mass(i) * sys.nodes().position(i).cross(sys.nodes().velocity(i));
  return L;
}

SymplecticEulerOptions unguarded(int energy_check_interval = 100) {
  SymplecticEulerOptions o;
  o.enforce_stable_step = false;
  o.health.energy_check_interval = energy_check_interval;
  return o;
}

// Block-Jacobi CG (the reference backend) with exactly this tolerance and limit, no floor.
ImplicitEulerOptions cg_options(double tolerance, int max_iterations = 1000) {
  ImplicitEulerOptions o;
  o.solver = solve::Backend::jacobi;
  o.cg_absolute_tolerance = 0;
  o.cg_tolerance = tolerance;
  o.cg_max_iterations = max_iterations;
  return o;
}

double total_energy(const System& sys) { return sys.kinetic_energy() + sys.potential_energy(); }

std::string fmt6(double v) {
  std::ostringstream os;
  os.precision(6);
  os << v;
  return os.str();
}

// ω_max of the undamped lattice: largest eigenvalue of M^{-1/2} K M^{-1/2}, dense.
double exact_omega(System& sys) {
  const Eigen::MatrixXd K = -assembled(sys, 1, 0, JacobianOptions{true, true});
  Eigen::VectorXd s(K.rows());
  for (Index i = 0; i < sys.nodes().size(); ++i) s.segment<3>(3 * i).setConstant(1 / std::sqrt(sys.nodes().mass(i)));
  const Eigen::MatrixXd A = s.asDiagonal() * K * s.asDiagonal();
  return std::sqrt(Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd>(A, Eigen::EigenvaluesOnly).eigenvalues().maxCoeff());
}

// The same for the free axes only (fixed rows and columns removed).
double exact_free_omega(System& sys) {
  const Eigen::MatrixXd K = -assembled(sys, 1, 0, JacobianOptions{true, true});
  std::vector<Eigen::Index> free;
  for (Index i = 0; i < sys.nodes().size(); ++i)
    for (int a = 0; a < 3; ++a)
      if (((sys.nodes().fixed(i) >> a) & 1) == 0) free.push_back(3 * Eigen::Index{i} + a);
  Eigen::MatrixXd A(free.size(), free.size());
  for (std::size_t r = 0; r < free.size(); ++r)
    for (std::size_t c = 0; c < free.size(); ++c)
      A(r, c) = K(free[r], free[c]) / std::sqrt(sys.nodes().mass(Index(free[r] / 3)) * sys.nodes().mass(Index(free[c] / 3)));
  return std::sqrt(Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd>(A, Eigen::EigenvaluesOnly).eigenvalues().maxCoeff());
}

}  // namespace

TEST_CASE("stable-step bound: Gershgorin constants of PHYSICS_NOTES §1.6 and a true upper bound") {
  const double E = 1e8, rho = 1000, a = 0.0125, wave = std::sqrt(E / rho);
  SUBCASE("single cube: bound and exact value are both 2.83") {
    System sys;
    cube_lattice(sys, 1, a, E, 0.3, rho);
    const StableStep st = sys.stable_step();
    CHECK(std::sqrt(st.stiffness_bound) * a / wave == Approx(2.83).epsilon(2e-3));
    CHECK(exact_omega(sys) * a / wave == Approx(2.83).epsilon(2e-3));
    CHECK(st.damping_bound == 0.0);
    CHECK(st.h_max == Approx(2 / std::sqrt(st.stiffness_bound)));
  }
  SUBCASE("4x4x4 grid: bound 2.93, exact 2.28") {
    System sys;
    cube_lattice(sys, 4, a, E, 0.3, rho);
    const StableStep st = sys.stable_step();
    const double c_bound = std::sqrt(st.stiffness_bound) * a / wave;
    const double c_exact = exact_omega(sys) * a / wave;
    CHECK(c_bound == Approx(2.93).epsilon(2e-3));
    CHECK(c_exact == Approx(2.28).epsilon(3e-3));
    CHECK(c_bound >= c_exact);
  }
  SUBCASE("with the seed's per-spring viscosity the bound stays below the simulated limit 0.154") {
    System sys;
    cube_lattice(sys, 8, a, E, 0.3, rho, SpringDamping::viscous);
    const double scaled = sys.stable_step().h_max * wave / a;
    CHECK(scaled <= 0.154);
    CHECK(scaled >= 0.5 * 0.154);  // and is not uselessly conservative
  }
}

TEST_CASE("stability rows: a spring pair added at once gives the rows of its blocks added one by one") {
  // add_pair is the springs' fast path; add_diagonal / add_offdiagonal the general one. Fixed
  // axes, a removed node (mass 0) and signed entries must give the same bound either way.
  std::mt19937 rng(17);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  const std::vector<double> mass{1.0, 2.5, 0.0, 0.7, 3.0};
  const std::vector<AxisMask> fixed{no_axes, axis_y, no_axes, axis_x | axis_z, all_axes};
  StabilityRows pairs(mass, fixed), blocks(mass, fixed);
  const std::vector<std::pair<Index, Index>> springs{{0, 1}, {1, 3}, {0, 2}, {3, 4}, {0, 3}, {2, 4}, {1, 4}};
  for (const auto& [i, j] : springs) {
    StabilityRows::SymBlock K, C;
    for (int e = 0; e < 6; ++e) {
      K[e] = u(rng);
      C[e] = u(rng);
    }
    pairs.add_pair(i, j, K, C);
    for (int w = 0; w < 2; ++w) {
      const auto& b = w == 0 ? K : C;
      Eigen::Matrix3d B;
      B << b[0], b[3], b[4], b[3], b[1], b[5], b[4], b[5], b[2];
      const auto which = static_cast<StabilityRows::Which>(w);
      blocks.add_diagonal(which, i, B);
      blocks.add_diagonal(which, j, B);
      blocks.add_offdiagonal(which, i, j, B);
    }
  }
  for (auto w : {StabilityRows::stiffness, StabilityRows::damping}) {
    CHECK(pairs.bound(w).value == Approx(blocks.bound(w).value).epsilon(1e-14));
    CHECK(pairs.bound(w).node == blocks.bound(w).node);
    CHECK(pairs.bound(w).value > 0);
  }
}

TEST_CASE("stability rows: the springs' eight-lane kernel gives the rows of the one-by-one path") {
  // Rows that fold slaves take every spring one by one (an empty fold folds nothing); plain rows
  // take the chunked springs eight at a time. Stretched, compressed and collapsed springs,
  // removed springs inside chunks, fixed axes and a massless node, each damping model.
  for (SpringDamping model : {SpringDamping::none, SpringDamping::viscous, SpringDamping::stiffness_proportional}) {
    CAPTURE(static_cast<int>(model));
    System sys;
    const BoxLattice L = cube_lattice(sys, 8, 0.1, 1e5, 0.3, 1000, model);
    if (model == SpringDamping::stiffness_proportional) L.springs->set_damping(model, 2e-3);
    for (Index j = 0; j <= 8; ++j) sys.nodes().fix(L.node(0, j, 0), axis_x | axis_z);
    sys.nodes().fix(L.node(8, 8, 8), all_axes);
    for (Index s = 0; s < L.springs->size(); s += 37) L.springs->remove(s);
    perturb(sys, 0.3 * 0.1 / 8, 0.0, 5);
    const Index removed = L.node(4, 4, 4);
    for (Index s = 0; s < L.springs->size(); ++s)
      if (L.springs->is_alive(s) && (L.springs->node_i(s) == removed || L.springs->node_j(s) == removed)) L.springs->remove(s);
    sys.nodes().remove(removed);
    // one spring collapsed to a point: no direction
    sys.nodes().set_position(L.node(3, 2, 1), sys.nodes().position(L.node(4, 2, 1)));
    sys.refresh();
    sys.compute_forces();  // the chunk plan is built
    REQUIRE(L.springs->num_in_runs() > L.springs->size() / 2);
    const SlaveExpansion none;
    StabilityRows lanes(sys.nodes().masses(), sys.nodes().fixed_masks());
    StabilityRows one_by_one(sys.nodes().masses(), sys.nodes().fixed_masks(), &none);
    L.springs->add_stability_rows(sys.state(), lanes);
    L.springs->add_stability_rows(sys.state(), one_by_one);
    for (auto w : {StabilityRows::stiffness, StabilityRows::damping}) {
      int differing = 0;
      for (Index i = 0; i < sys.nodes().size(); ++i)
        for (int a = 0; a < 3; ++a)
          differing += lanes.row(w, i, a) == Approx(one_by_one.row(w, i, a)).epsilon(1e-13) ? 0 : 1;
      CHECK(differing == 0);
      CHECK(lanes.bound(w).value == Approx(one_by_one.bound(w).value).epsilon(1e-13));
    }
    CHECK(lanes.bound(StabilityRows::stiffness).value > 0);
    CHECK((lanes.bound(StabilityRows::damping).value > 0) == (model != SpringDamping::none));
  }
}

// The bound as rows are read one by one (node, then axis): the first largest row, a NaN row
// taken if it comes before any positive one. What StabilityRows::bound must give.
StabilityRows::Bound bound_one_by_one(const StabilityRows& rows, StabilityRows::Which w, std::span<const double> mass,
                                      std::span<const AxisMask> fixed) {
  StabilityRows::Bound out;
  for (Index i = 0; i < mass.size(); ++i)
    for (int a = 0; a < 3; ++a) {
      if (!(mass[i] > 0) || ((fixed[i] >> a) & 1u) != 0) continue;
      const double r = rows.row(w, i, a);
      if (r > out.value || (std::isnan(r) && out.node == invalid_index)) {
        out.value = r;
        out.node = i;
      }
    }
  return out;
}

TEST_CASE("stability rows: the bound is the first largest row over blocks of nodes, and a NaN row is named") {
  // 1331 nodes: several of bound()'s blocks of 256. Random states, fixed axes and a removed
  // node; then equal largest rows in two blocks (the first wins), then a NaN.
  for (unsigned seed = 1; seed <= 4; ++seed) {
    CAPTURE(seed);
    System sys;
    const BoxLattice L = cube_lattice(sys, 10, 0.1, 1e5, 0.3, 1000, SpringDamping::viscous);
    for (Index j = 0; j <= 10; ++j) sys.nodes().fix(L.node(0, j, 0), axis_x | axis_z);
    perturb(sys, 0.2 * 0.1 / 10, 0.0, seed);
    const Index removed = L.node(5, 5, 5);
    for (Index s = 0; s < L.springs->size(); ++s)
      if (L.springs->node_i(s) == removed || L.springs->node_j(s) == removed) L.springs->remove(s);
    sys.nodes().remove(removed);
    sys.refresh();
    sys.compute_forces();  // the chunk plan is built
    StabilityRows rows(sys.nodes().masses(), sys.nodes().fixed_masks());
    L.springs->add_stability_rows(sys.state(), rows);
    for (auto w : {StabilityRows::stiffness, StabilityRows::damping}) {
      const auto ref = bound_one_by_one(rows, w, sys.nodes().masses(), sys.nodes().fixed_masks());
      REQUIRE(ref.node != invalid_index);
      CHECK(rows.bound(w).value == ref.value);
      CHECK(rows.bound(w).node == ref.node);
    }
  }
  // Two nodes far apart (different blocks) with the same largest row: the lower one is named.
  {
    const std::vector<double> mass(600, 1.0);
    const std::vector<AxisMask> fixed(600, no_axes);
    StabilityRows rows(mass, fixed);
    Eigen::Matrix3d B = Eigen::Matrix3d::Identity();
    for (Index i = 0; i < 600; ++i) rows.add_diagonal(StabilityRows::stiffness, i, (1.0 + 0.001 * (i % 7)) * B);
    rows.add_diagonal(StabilityRows::stiffness, 510, 5.0 * B);  // 510 ≡ 300 (mod 7): equal rows
    rows.add_diagonal(StabilityRows::stiffness, 300, 5.0 * B);
    rows.add_diagonal(StabilityRows::stiffness, 301, 4.0 * B);
    const auto b = rows.bound(StabilityRows::stiffness);
    CHECK(b.node == 300);
    CHECK(b.value == rows.row(StabilityRows::stiffness, 510, 2));
    // A NaN row after the largest is not the bound (as the rows are read one by one); a NaN row
    // before any positive row is.
    rows.add_diagonal(StabilityRows::stiffness, 400, std::nan("") * B);
    CHECK(rows.bound(StabilityRows::stiffness).node == bound_one_by_one(rows, StabilityRows::stiffness, mass, fixed).node);
    CHECK(rows.bound(StabilityRows::stiffness).node == 300);
    StabilityRows first_nan(mass, fixed);
    first_nan.add_diagonal(StabilityRows::stiffness, 0, std::nan("") * B);
    for (Index i = 1; i < 600; ++i) first_nan.add_diagonal(StabilityRows::stiffness, i, B);
    CHECK(first_nan.bound(StabilityRows::stiffness).node == 0);
    CHECK(std::isnan(first_nan.bound(StabilityRows::stiffness).value));
  }
}

TEST_CASE("semi-implicit steps above the bound are refused with the bound in the message") {
  System sys;
  cube_lattice(sys, 3, 0.1, 1e5, 0.3, 1000, SpringDamping::viscous);
  perturb(sys, 1e-3, 0.01, 3);
  const Eigen::VectorXd x0 = sys.nodes().positions_flat();
  const double bound = sys.stable_step().h_max;
  SymplecticEuler se;
  try {
    (void)se.step(sys, 1.01 * bound);
    FAIL("the step was not refused");
  } catch (const StabilityError& e) {
    CHECK(e.bound() == Approx(bound).epsilon(1e-12));
    CHECK(std::string(e.what()).find(fmt6(bound)) != std::string::npos);
  }
  CHECK(sys.nodes().positions_flat() == x0);
  // Opted out, the same step is taken.
  SymplecticEuler free_run(unguarded());
  (void)free_run.step(sys, 1.01 * bound);
  CHECK(sys.nodes().positions_flat() != x0);
}

TEST_CASE("just below the bound, semi-implicit runs stay bounded; well above it, the blow-up is caught") {
  for (SpringDamping model : {SpringDamping::none, SpringDamping::viscous}) {
    System sys;
    const BoxLattice L = cube_lattice(sys, 3, 0.1, 1e5, 0.3, 1000, model);
    for (Index j = 0; j <= 3; ++j)
      for (Index k = 0; k <= 3; ++k) sys.nodes().fix(L.node(0, j, k));
    perturb(sys, 1e-4, 0.005, 9);
    const double e0 = total_energy(sys);
    const double h = 0.99 * sys.stable_step().h_max;
    SymplecticEuler se;
    double early = 0, late = 0;
    for (int n = 0; n < 6000; ++n) {
      (void)se.step(sys, h);
      (n < 2000 ? early : late) = std::max(n < 2000 ? early : late, total_energy(sys));
    }
    if (model == SpringDamping::none) {
      // Each mode conserves v² + ω²x² - hω²xv, so its plain energy stays within
      // (1 + hω/2)/(1 - hω/2) of its start; ω_max ≤ the (exact) free-system value.
      const double w = exact_free_omega(sys);
      CHECK(h * w < 2.0);
      CHECK(std::max(early, late) <= (1 + h * w / 2) / (1 - h * w / 2) * e0);
    } else {
      CHECK(late <= early);
      CHECK(total_energy(sys) < 0.5 * e0);
    }
  }
  // The true limit is about 1.3x the bound for this lattice (undamped); 1.6x must blow up and
  // be stopped by the watchdog (energy) or the finiteness check.
  System sys;
  const BoxLattice L = cube_lattice(sys, 3, 0.1, 1e5, 0.3, 1000);
  for (Index j = 0; j <= 3; ++j)
    for (Index k = 0; k <= 3; ++k) sys.nodes().fix(L.node(0, j, k));
  perturb(sys, 1e-4, 0.0, 4);
  const double bound = sys.stable_step().h_max;
  SymplecticEuler se(unguarded(10));
  bool caught = false;
  try {
    for (int n = 0; n < 100000; ++n) (void)se.step(sys, 1.6 * bound);
  } catch (const BlowupError& e) {
    caught = true;
    CHECK(e.node() != invalid_index);
    CHECK(std::string(e.what()).find("node " + std::to_string(e.node())) != std::string::npos);
  }
  CHECK(caught);
}

TEST_CASE("free lattice: linear momentum conserved by both integrators, angular momentum by symplectic Euler") {
  System sys;
  cube_lattice(sys, 3, 0.1, 1e5, 0.3, 1000, SpringDamping::viscous);
  perturb(sys, 5e-3, 0.2, 17);
  const Vector3d p0 = momentum(sys), L0 = angular_momentum(sys);
  double pscale = 0, Lscale = 0;
  for (Index i = 0; i < sys.nodes().size(); ++i) {
    pscale += sys.nodes().mass(i) * sys.nodes().velocity(i).norm();
    Lscale += sys.nodes().mass(i) * sys.nodes().position(i).norm() * sys.nodes().velocity(i).norm();
  }
  const double h = 0.5 * sys.stable_step().h_max;
  SymplecticEuler se;
  for (int n = 0; n < 2000; ++n) (void)se.step(sys, h);
  CHECK((momentum(sys) - p0).norm() <= 1e-13 * pscale);
  CHECK((angular_momentum(sys) - L0).norm() <= 1e-12 * Lscale);
  // Implicit Euler conserves momentum up to the CG residual (Σ m ΔV = -Σ r): solve tightly.
  LinearlyImplicitEuler ie(cg_options(1e-13, 10000));
  const Vector3d p1 = momentum(sys);
  for (int n = 0; n < 200; ++n) (void)ie.step(sys, 1e-3);
  CHECK((momentum(sys) - p1).norm() <= 1e-11 * pscale);
}

TEST_CASE("implicit Euler on a linear oscillator: energy ratio (1+h²ω²)^-n") {
  System sys;
  const double k = 250.0, m = 0.4, l = 0.3, omega = std::sqrt(k / m), h = 0.6 / omega;
  sys.nodes().add({0, 0, 0}, {0, 0, 0}, 1.0);
  sys.nodes().fix(0);
  sys.nodes().add({l + 0.05, 0, 0}, {0.3, 0, 0}, m);
  sys.add<Springs>().add(0, 1, k, l);
  auto energy = [&] {
    const double d = sys.nodes().position(1).norm();
    return 0.5 * m * sys.nodes().velocity(1).squaredNorm() + 0.5 * k * (d - l) * (d - l);
  };
  CHECK(energy() == Approx(total_energy(sys)).epsilon(1e-14));
  const double e0 = energy();
  LinearlyImplicitEuler ie;
  for (int n = 0; n < 50; ++n) {
    const StepReport r = ie.step(sys, h);
    CHECK(r.cg_converged);
  }
  const double ratio = energy() / e0;
  CHECK(ratio == Approx(std::pow(1 + 0.36, -50)).epsilon(1e-9));
  CHECK(ratio == Approx(2.10404e-7).epsilon(5e-6));
}

TEST_CASE("fixed axes stay exactly fixed under implicit and semi-implicit steps") {
  System sys;
  const BoxLattice L = cube_lattice(sys, 3, 0.1, 1e5, 0.3, 1000, SpringDamping::viscous);
  sys.add<Gravity>(Vector3d(0, 0, -9.81));
  for (Index j = 0; j <= 3; ++j)
    for (Index k = 0; k <= 3; ++k) sys.nodes().fix(L.node(0, j, k));
  const Index roller = L.node(3, 3, 3);
  sys.nodes().fix(roller, axis_z | axis_x);
  perturb(sys, 1e-3, 0.05, 2);
  const Eigen::VectorXd x0 = sys.nodes().positions_flat();
  auto check_fixed = [&] {
    for (Index j = 0; j <= 3; ++j)
      for (Index k = 0; k <= 3; ++k)
        for (int a = 0; a < 3; ++a) CHECK(sys.nodes().x()[3 * L.node(0, j, k) + a] == x0[3 * L.node(0, j, k) + a]);
    CHECK(sys.nodes().x()[3 * roller] == x0[3 * roller]);
    CHECK(sys.nodes().x()[3 * roller + 2] == x0[3 * roller + 2]);
  };
  LinearlyImplicitEuler ie;
  for (int n = 0; n < 30; ++n) (void)ie.step(sys, 1e-3);
  check_fixed();
  CHECK(sys.nodes().x()[3 * roller + 1] != x0[3 * roller + 1]);  // the free axis moved
  SymplecticEuler se;
  const double h = 0.5 * sys.stable_step().h_max;
  for (int n = 0; n < 200; ++n) (void)se.step(sys, h);
  check_fixed();
}

TEST_CASE("a fixed axis with a prescribed velocity is kinematic in both integrators") {
  System sys;
  const BoxLattice L = cube_lattice(sys, 2, 0.1, 1e5, 0.3, 1000, SpringDamping::viscous);
  const Index driver = L.node(2, 2, 2);
  sys.nodes().fix(driver);
  sys.nodes().set_velocity(driver, {0.0, 0.0, 0.2});
  const Vector3d p0 = sys.nodes().position(driver);
  SymplecticEuler se;
  LinearlyImplicitEuler ie;
  const double h_se = 0.5 * sys.stable_step().h_max, h_ie = 1e-3;
  for (int n = 0; n < 40; ++n) (void)se.step(sys, h_se);
  for (int n = 0; n < 40; ++n) (void)ie.step(sys, h_ie);
  CHECK(sys.nodes().velocity(driver) == Vector3d(0.0, 0.0, 0.2));
  CHECK(sys.nodes().position(driver).z() == Approx(p0.z() + 0.2 * 40 * (h_se + h_ie)).epsilon(1e-12));
  CHECK(sys.nodes().position(driver).x() == p0.x());
  CHECK(sys.nodes().velocity(L.node(1, 1, 1)).norm() > 0);  // it drags the others
}

TEST_CASE("mass damping: exact discrete decay in both integrators (Rayleigh α term, correct sign)") {
  const double alpha = 3.0, h = 0.01;
  for (int scheme = 0; scheme < 2; ++scheme) {
    System sys;
    const BoxLattice L = cube_lattice(sys, 2, 0.1, 1e4, 0.3, 1000);
    (void)L;
    sys.add<MassDamping>(alpha);
    for (Index i = 0; i < sys.nodes().size(); ++i) sys.nodes().set_velocity(i, {0.5, -0.2, 0.1});  // rigid
    SymplecticEuler se(unguarded());
    LinearlyImplicitEuler ie(cg_options(1e-12));
    for (int n = 0; n < 20; ++n) {
      if (scheme == 0) (void)se.step(sys, h);
      else (void)ie.step(sys, h);
    }
    const double factor = scheme == 0 ? std::pow(1 - h * alpha, 20) : std::pow(1 + h * alpha, -20);
    CHECK(sys.nodes().velocity(5).x() == Approx(0.5 * factor).epsilon(1e-9));
  }
}

TEST_CASE("Rayleigh damping C = αM + βK_s removes energy under both integrators") {
  System sys;
  BoxLatticeSpec s;
  s.nx = s.ny = s.nz = 3;
  s.lx = s.ly = s.lz = 0.1;
  s.E = 1e5;
  s.rho = 1000;
  s.damping = SpringDamping::stiffness_proportional;
  s.rayleigh_beta = 2e-3;
  build_box_lattice(sys, s);
  sys.add<MassDamping>(0.5);
  perturb(sys, 3e-3, 0.1, 5);
  double e = total_energy(sys);
  LinearlyImplicitEuler ie;
  for (int n = 0; n < 20; ++n) {
    (void)ie.step(sys, 1e-3);
    const double en = total_energy(sys);
    CHECK(en < e);
    e = en;
  }
  SymplecticEuler se;
  const double h = 0.5 * sys.stable_step().h_max;
  for (int w = 0; w < 5; ++w) {
    for (int n = 0; n < 200; ++n) (void)se.step(sys, h);
    const double en = total_energy(sys);
    CHECK(en < e);
    e = en;
  }
}

TEST_CASE("CG that misses its tolerance is reported with its residual") {
  System sys;
  cube_lattice(sys, 4, 0.0125, 1e8, 0.3, 1000);
  perturb(sys, 1e-4, 0.1, 6);
  const Eigen::VectorXd x0 = sys.nodes().positions_flat(), v0 = sys.nodes().velocities_flat();
  LinearlyImplicitEuler ie(cg_options(1e-6, 2));
  try {
    (void)ie.step(sys, 1e-3);
    FAIL("non-convergence was not reported");
  } catch (const SolverError& e) {
    CHECK(e.iterations() == 2);
    CHECK(e.residual() > 1e-6);
    CHECK(std::string(e.what()).find("relative residual " + fmt6(e.residual())) != std::string::npos);
  }
  CHECK(sys.nodes().positions_flat() == x0);
  CHECK(sys.nodes().velocities_flat() == v0);
  ie.options().throw_on_cg_failure = false;
  const StepReport r = ie.step(sys, 1e-3);
  CHECK_FALSE(r.cg_converged);
  CHECK(r.cg_iterations == 2);
  CHECK(r.cg_relative_residual > 1e-6);
  ie.options().cg_max_iterations = 1000;
  const StepReport ok = ie.step(sys, 1e-3);
  CHECK(ok.cg_converged);
  CHECK(ok.cg_relative_residual <= 1e-6);
  CHECK(ok.cg_iterations > 2);
}

TEST_CASE("a NaN injected into the state is caught before use, naming the node") {
  for (int scheme = 0; scheme < 2; ++scheme) {
    System sys;
    cube_lattice(sys, 2, 0.1, 1e5, 0.3, 1000, SpringDamping::viscous);
    SymplecticEuler se;
    LinearlyImplicitEuler ie;
    for (int n = 0; n < 3; ++n) {
      if (scheme == 0) (void)se.step(sys, 1e-4);
      else (void)ie.step(sys, 1e-3);
    }
    sys.nodes().x()[3 * 13 + 1] = std::nan("");
    const Eigen::VectorXd v0 = sys.nodes().velocities_flat();
    try {
      if (scheme == 0) (void)se.step(sys, 1e-4);
      else (void)ie.step(sys, 1e-3);
      FAIL("NaN not caught");
    } catch (const BlowupError& e) {
      CHECK(e.node() == 13);
      CHECK(e.quantity() == "position");
      CHECK(std::string(e.what()).find("position of node 13 is not finite") != std::string::npos);
    }
    CHECK(sys.nodes().velocities_flat() == v0);
    sys.nodes().v()[3 * 4] = INFINITY;
    sys.nodes().x()[3 * 13 + 1] = 0.1;
    CHECK_THROWS_WITH_AS((void)se.step(sys, 1e-4), doctest::Contains("velocity of node 4"), BlowupError);
  }
}

TEST_CASE("after an update found finite, the next step checks only the forces; write access brings the full check back") {
  for (int scheme = 0; scheme < 2; ++scheme) {
    System sys;
    const BoxLattice L = cube_lattice(sys, 2, 0.1, 1e5, 0.3, 1000, SpringDamping::viscous);
    // A node no term reads (gravity reads masses only): a NaN there never reaches the forces.
    const Index lone = sys.nodes().add({5, 5, 5}, {0, 0, 0}, 1.0);
    sys.add<Gravity>(Eigen::Vector3d(0, 0, -9.81));
    SymplecticEuler se;
    LinearlyImplicitEuler ie;
    const auto step = [&] {
      if (scheme == 0) (void)se.step(sys, 1e-4);
      else (void)ie.step(sys, 1e-3);
    };
    CHECK_FALSE(sys.nodes().state_known_finite());
    step();
    CHECK(sys.nodes().state_known_finite());
    sys.nodes().set_position(0, sys.nodes().position(0));  // checked setter
    CHECK(sys.nodes().state_known_finite());
    const auto x = sys.nodes().x();  // write access: the flag is gone until the next update
    CHECK_FALSE(sys.nodes().state_known_finite());
    step();
    CHECK(sys.nodes().state_known_finite());
    // A NaN written through the span held across the step, at a node springs read: the forces
    // carry it, their check stops the step before anything changes, and the report names the
    // position it came from.
    const Index inner = L.node(1, 1, 1);
    x[3 * inner] = std::nan("");
    const NodeTable& read = sys.nodes();  // reading through const access keeps the flag
    const std::vector<double> v0(read.v().begin(), read.v().end());
    REQUIRE(read.state_known_finite());
    CHECK_THROWS_WITH_AS(step(), doctest::Contains(("position of node " + std::to_string(inner)).c_str()), BlowupError);
    CHECK(std::equal(v0.begin(), v0.end(), read.v().begin()));
    x[3 * inner] = 0.1;
    sys.nodes().mark_state_finite();
    // At the node no term reads, the step's own update finds it, and the next step names it.
    x[3 * lone + 2] = std::nan("");
    step();
    CHECK_FALSE(sys.nodes().state_known_finite());
    CHECK_THROWS_WITH_AS(step(), doctest::Contains(("position of node " + std::to_string(lone)).c_str()), BlowupError);
  }
}

TEST_CASE("rest state is an equilibrium and stays put") {
  System sys;
  const BoxLattice L = cube_lattice(sys, 3, 0.1, 1e5, 0.3, 1000, SpringDamping::viscous);
  sys.compute_forces();
  const double kscale = L.springs->stiffness(0) * 0.1;
  CHECK(sys.nodes().forces().cwiseAbs().maxCoeff() <= 1e-13 * kscale);
  const Eigen::VectorXd x0 = sys.nodes().positions_flat();
  SymplecticEuler se;
  LinearlyImplicitEuler ie;
  for (int n = 0; n < 100; ++n) {
    (void)se.step(sys, 1e-4);
    (void)ie.step(sys, 1e-3);
  }
  CHECK((sys.nodes().positions_flat() - x0).cwiseAbs().maxCoeff() <= 1e-14);
}

TEST_CASE("integrators refuse bad steps and non-symmetric solver matrices; the pattern is reused") {
  System sys;
  cube_lattice(sys, 2, 0.1, 1e5, 0.3, 1000, SpringDamping::viscous);
  SymplecticEuler se;
  LinearlyImplicitEuler ie;
  for (double h : {0.0, -1e-3, std::nan(""), double(INFINITY)}) {
    CHECK_THROWS_AS((void)se.step(sys, h), InputError);
    CHECK_THROWS_AS((void)ie.step(sys, h), InputError);
  }
  const StepReport first = ie.step(sys, 1e-3);
  const StepReport second = ie.step(sys, 1e-3);
  CHECK_FALSE(second.pattern_rebuilt);
  (void)first;
  Springs& sp = static_cast<Springs&>(*sys.terms()[0]);
  sp.add(0, 26, 10.0, 0.3);
  CHECK(ie.step(sys, 1e-3).pattern_rebuilt);
  ie.options().jacobian.drop_viscous_position_terms = false;
  CHECK_THROWS_WITH_AS((void)ie.step(sys, 1e-3), doctest::Contains("'springs'"), InputError);
}

}  // namespace test_integrators
