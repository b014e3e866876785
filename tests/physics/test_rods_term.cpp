// The Rods force term: forces exact for the reduced energy min_θ E (finite differences),
// the assembled Jacobian (exact for a straight rod; with the Schur complement over θ, exact
// for a curved one), zero net force and torque, and a cantilever rod under gravity settling,
// under the linearly implicit integrator, onto the static solution.
#include <chrono>
#include <cmath>
#include <numbers>
#include <random>
#include <vector>

#include <Eigen/Dense>
#include <Eigen/Geometry>
#include <doctest/doctest.h>

#include "helpers.hpp"
#include "sewn/physics/errors.hpp"
#include "sewn/physics/rods/rods_term.hpp"
#include "sewn/physics/rods/static_solve.hpp"

namespace test_rods_term {

using namespace sewn::physics;
using namespace sewn::physics::rods;

namespace {

// A helical arc of n vertices as the rest shape (natural curvature and twist), added to sys.
Rods& helix_rod(System& sys, int n, std::vector<Index>& ids) {
  for (int i = 0; i < n; ++i) {
    const double s = 0.6 * i;
    ids.push_back(sys.nodes().add(Vec3(0.3 * std::cos(s), 0.3 * std::sin(s), 0.05 * i), Vec3::Zero(), 0.01));
  }
  Rods& rods = sys.add<Rods>();
  (void)rods.add_rod(ids, sys.nodes().x(), false, Section::elliptic(1e6, 0.3, 0.02, 0.01));
  return rods;
}

void perturb(System& sys, std::mt19937& rng, double size) {
  std::normal_distribution<double> n(0, size);
  for (double& v : sys.nodes().x()) v += n(rng);
}

}  // namespace

TEST_CASE("rods term: forces are minus the gradient of the reduced energy") {
  System sys;
  std::vector<Index> ids;
  Rods& rods = helix_rod(sys, 7, ids);
  rods.rod(0).fix_theta(0);
  rods.rod(0).fix_theta(5);
  rods.rod(0).set_theta(5, 1.3);  // an end twisted by 1.3 rad
  std::mt19937 rng(11);
  perturb(sys, rng, 0.01);
  const Eigen::VectorXd f = test::forces(sys);
  auto x = sys.nodes().x();
  const double h = 1e-6;
  double err = 0;
  for (std::size_t k = 0; k < x.size(); ++k) {
    const double keep = x[k];
    x[k] = keep + h;
    const double Ep = sys.potential_energy();
    x[k] = keep - h;
    const double Em = sys.potential_energy();
    x[k] = keep;
    err = std::max(err, std::abs(-(Ep - Em) / (2 * h) - f[static_cast<Eigen::Index>(k)]));
  }
  CHECK(err < 1e-6 * f.cwiseAbs().maxCoeff());
  // Net force and torque vanish (θ is at its minimum: no generalised torque on the angles;
  // the clamped angles carry the end torque, so the rod's torque balance includes them: check
  // force only here, torque with free angles below).
  Vec3 F = Vec3::Zero();
  for (Index i : ids) F += Vec3(f[3 * i], f[3 * i + 1], f[3 * i + 2]);
  CHECK(F.norm() < 1e-9 * f.norm());
}

TEST_CASE("rods term: with free angles, zero net force and torque") {
  System sys;
  std::vector<Index> ids;
  (void)helix_rod(sys, 8, ids);
  std::mt19937 rng(12);
  perturb(sys, rng, 0.02);
  const Eigen::VectorXd f = test::forces(sys);
  Vec3 F = Vec3::Zero(), T = Vec3::Zero();
  for (Index i : ids) {
    const Vec3 fi(f[3 * i], f[3 * i + 1], f[3 * i + 2]);
    F += fi;
    T += sys.nodes().position(i).cross(fi);
  }
  CHECK(f.norm() > 0);
  CHECK(F.norm() < 1e-9 * f.norm());
  CHECK(T.norm() < 1e-8 * f.norm());
}

TEST_CASE("rods term: assembled Jacobian, exact for a straight rod and with the Schur complement") {
  SUBCASE("straight, stretched: nothing dropped") {
    System sys;
    std::vector<Index> ids;
    for (int i = 0; i < 5; ++i) ids.push_back(sys.nodes().add(Vec3(0.1 * i, 0, 0), Vec3::Zero(), 0.01));
    Rods& rods = sys.add<Rods>();
    (void)rods.add_rod(ids, sys.nodes().x(), false, Section::circular(1e6, 0.3, 0.01));
    for (Index i : ids) sys.nodes().set_position(i, Vec3(0.11 * i, 0, 0));
    const Eigen::MatrixXd A = test::assembled(sys, 1.0, 0.0, {});
    const Eigen::MatrixXd J = test::finite_difference(sys, false, 1e-7);
    CHECK((A - J).cwiseAbs().maxCoeff() < 1e-5 * J.cwiseAbs().maxCoeff());
  }
  SUBCASE("curved and twisted: −H_xx + H_xθ H_θθ⁻¹ H_θx is the exact Jacobian") {
    System sys;
    std::vector<Index> ids;
    Rods& rods = helix_rod(sys, 6, ids);
    rods.set_project_hessians(false);
    rods.rod(0).fix_theta(0);
    std::mt19937 rng(13);
    perturb(sys, rng, 0.01);
    const Eigen::MatrixXd A = test::assembled(sys, 1.0, 0.0, {});  // also solves θ here
    const Rod& rod = rods.rod(0);
    const Points x = rods.gather(0, sys.nodes().x());
    Eigen::VectorXd g;
    std::vector<Eigen::Triplet<double>> trips;
    (void)rod.evaluate(x, g, &trips);
    Eigen::SparseMatrix<double> Hs(rod.num_dofs(), rod.num_dofs());
    Hs.setFromTriplets(trips.begin(), trips.end());
    const Eigen::MatrixXd H(Hs);
    const int nx = 3 * rod.num_vertices();
    std::vector<int> th;  // free angles
    for (int j = 0; j < rod.num_edges(); ++j)
      if (!rod.theta_fixed(j)) th.push_back(nx + j);
    Eigen::MatrixXd Hxt(nx, static_cast<Eigen::Index>(th.size())), Htt(th.size(), th.size());
    for (std::size_t a = 0; a < th.size(); ++a) {
      Hxt.col(static_cast<Eigen::Index>(a)) = H.block(0, th[a], nx, 1);
      for (std::size_t b = 0; b < th.size(); ++b) Htt(static_cast<Eigen::Index>(a), static_cast<Eigen::Index>(b)) = H(th[a], th[b]);
    }
    const Eigen::MatrixXd schur = Hxt * Htt.ldlt().solve(Hxt.transpose());
    const Eigen::MatrixXd J = test::finite_difference(sys, false, 1e-7);
    // Node ids are 0..n−1 here, so rod DOFs and system DOFs coincide.
    CHECK((A + schur - J).cwiseAbs().maxCoeff() < 1e-5 * J.cwiseAbs().maxCoeff());
    CHECK(schur.cwiseAbs().maxCoeff() > 1e-3 * J.cwiseAbs().maxCoeff());  // the term is not negligible
  }
}

TEST_CASE("rods term: a cantilever rod under gravity settles onto the static solution") {
  const int n = 11;
  const double L = 0.5, rho = 1000, r = 0.005;
  const Section sec = Section::circular(1e7, 0.3, r);
  System sys;
  std::vector<Index> ids;
  const double m = rho * std::numbers::pi * r * r * L / (n - 1);
  for (int i = 0; i < n; ++i) ids.push_back(sys.nodes().add(Vec3(L * i / (n - 1), 0, 0), Vec3::Zero(), m));
  sys.nodes().fix(ids[0]);
  sys.nodes().fix(ids[1]);
  Rods& rods = sys.add<Rods>();
  (void)rods.add_rod(ids, sys.nodes().x(), false, sec);
  rods.rod(0).fix_theta(0);
  const Vec3 g(0, 0, -9.81);
  sys.add<Gravity>(g);
  sys.add<MassDamping>(20.0);
  LinearlyImplicitEuler euler;
  for (int s = 0; s < 3000; ++s) (void)euler.step(sys, 2e-3);
  // The same rod solved statically under its nodes' weights.
  Points x(3, n);
  for (int i = 0; i < n; ++i) x.col(i) = Vec3(L * i / (n - 1), 0, 0);
  Rod rod(x, false, sec);
  rod.fix_theta(0);
  StaticProblem p;
  p.fixed.assign(n, no_axes);
  p.fixed[0] = p.fixed[1] = all_axes;
  p.forces = Points::Zero(3, n);
  for (int i = 0; i < n; ++i) p.forces.col(i) = sys.nodes().mass(ids[static_cast<std::size_t>(i)]) * g;
  (void)solve_static(rod, x, p);
  const double tip_static = x(2, n - 1);
  const double tip_dynamic = sys.nodes().position(ids.back())[2];
  MESSAGE("cantilever rod: static tip " << tip_static << " m, settled " << tip_dynamic << " m");
  CHECK(tip_static < -0.01);  // a real deflection
  CHECK(tip_dynamic == doctest::Approx(tip_static).epsilon(1e-4));
  CHECK(sys.kinetic_energy() < 1e-12);
}

TEST_CASE("rods: bad rods are refused with the vertex or edge named") {
  const Section sec = Section::circular(1e6, 0.3, 0.01);
  Points one(3, 1);
  one.col(0) = Vec3::Zero();
  CHECK_THROWS_WITH_AS(Rod(one, false, sec), doctest::Contains("at least 2 vertices"), InputError);
  Points dup(3, 3);
  dup << 0, 1, 1, 0, 0, 0, 0, 0, 0;
  CHECK_THROWS_WITH_AS(Rod(dup, false, sec), doctest::Contains("edge 1 has zero rest length"), InputError);
  Points fold(3, 3);
  fold << 0, 1, 0, 0, 0, 0, 0, 0, 0;
  CHECK_THROWS_WITH_AS(Rod(fold, false, sec), doctest::Contains("folds back on itself at vertex 1"), InputError);
  Points ok(3, 3);
  ok << 0, 1, 2, 0, 0.1, 0, 0, 0, 0;
  const std::vector<Vec3> one_director{Vec3(0, 0, 1)};
  CHECK_THROWS_WITH_AS(Rod(ok, false, sec, one_director), doctest::Contains("1 rest directors given for 2 edges"), InputError);
  const std::vector<Vec3> parallel{Vec3(1, 0.1, 0), Vec3(0, 0, 1)};
  CHECK_THROWS_WITH_AS(Rod(ok, false, sec, parallel), doctest::Contains("edge 0"), InputError);
  System sys;
  for (int i = 0; i < 3; ++i) (void)sys.nodes().add(ok.col(i), Vec3::Zero(), 1.0);
  Rods& rods = sys.add<Rods>();
  const std::vector<Index> twice{0, 1, 0};
  CHECK_THROWS_WITH_AS((void)rods.add_rod(twice, sys.nodes().x(), false, sec), doctest::Contains("visits node 0 twice"), InputError);
  const std::vector<Index> outside{0, 1, 7};
  CHECK_THROWS_WITH_AS((void)rods.add_rod(outside, sys.nodes().x(), false, sec), doctest::Contains("node 7"), InputError);
  CHECK(rods.num_rods() == 0);
}

TEST_CASE("rods term: cost of a force evaluation on a 101-vertex rod (report only)") {
  System sys;
  std::vector<Index> ids;
  Rods& rods = helix_rod(sys, 101, ids);
  rods.rod(0).fix_theta(0);
  std::mt19937 rng(2);
  std::vector<double> f(3 * ids.size());
  const int reps = 20;
  double sink = 0;
  rods.add_forces(sys.nodes().state(), f);  // the first solve starts from θ = 0
  double best = 1e9;  // the machine is shared: the fastest call is the least disturbed
  for (int k = 0; k < reps; ++k) {
    perturb(sys, rng, 1e-4);  // a new state: the twist is solved again, warm-started
    std::fill(f.begin(), f.end(), 0.0);
    const auto t0 = std::chrono::steady_clock::now();
    rods.add_forces(sys.nodes().state(), f);
    const auto t1 = std::chrono::steady_clock::now();
    best = std::min(best, std::chrono::duration<double, std::milli>(t1 - t0).count());
    sink += f[3];
  }
  MESSAGE("101-vertex rod: forces with the twist solve (fastest of " << reps << ") " << best << " ms");
  CHECK(std::isfinite(sink));
}

TEST_CASE("rods term: a hanging rod twisted past pi and back, under the implicit integrator") {
  // The top edge is clamped; the bottom edge's angle is driven 0 → 3π → 0. The rod stays
  // straight, so its elastic energy follows GJΦ²/(2 L_tw) (plus the small stretch under its
  // weight) with no jump at π, and returns to its start.
  const int n = 11;
  const double L = 0.5, r = 0.005;
  const Section sec = Section::circular(1e7, 0.3, r);
  System sys;
  Rods& rods = test::hanging_clamped_rod(sys, n, L, sec);
  const int last = n - 2;
  sys.add<Gravity>(Vec3(0, 0, -9.81));
  sys.add<MassDamping>(10.0);
  LinearlyImplicitEuler euler;
  // The driven angle does work that the energy watchdog does not count as income (it knows
  // external fields only), so the watchdog is off here.
  euler.options().health.energy_check_interval = 0;
  for (int s = 0; s < 300; ++s) (void)euler.step(sys, 1e-3);  // settle under gravity
  const double E0 = sys.potential_energy(EnergyKind::internal);
  double Ltw = 0;
  for (int k = 0; k < rods.rod(0).num_stencils(); ++k) Ltw += rods.rod(0).stencil_rest(k).voronoi;
  const int ramp = 600;
  const double Phi_max = 3 * std::numbers::pi;
  double prev = E0, max_jump = 0, at_peak = 0;
  auto drive = [&](int k) {
    rods.rod(0).set_theta(last, Phi_max * k / ramp);
    (void)euler.step(sys, 1e-3);
    const double E = sys.potential_energy(EnergyKind::internal);
    max_jump = std::max(max_jump, std::abs(E - prev));
    prev = E;
  };
  for (int k = 1; k <= ramp; ++k) drive(k);
  for (int s = 0; s < 200; ++s) (void)euler.step(sys, 1e-3);  // let it settle at the peak
  at_peak = sys.potential_energy(EnergyKind::internal) - E0;
  prev = sys.potential_energy(EnergyKind::internal);
  for (int k = ramp - 1; k >= 0; --k) drive(k);
  for (int s = 0; s < 300; ++s) (void)euler.step(sys, 1e-3);
  const double twist = sec.GJ * Phi_max * Phi_max / (2 * Ltw);
  MESSAGE("hanging rod twisted by 3 pi: energy gained " << at_peak << " J, GJ Phi^2/(2 L_tw) " << twist
                                                      << " J; largest change in one step " << max_jump << " J");
  CHECK(at_peak == doctest::Approx(twist).epsilon(1e-3));
  CHECK(max_jump < 0.02 * twist);  // ~ twist · 2·(1/600): smooth, no jump
  CHECK(sys.potential_energy(EnergyKind::internal) == doctest::Approx(E0).epsilon(1e-6));
}

TEST_CASE("rods term: a seeded random sequence of rigid rotations keeps the energy (frames tracked)") {
  // Free angles: the energy of a rigidly moved rod must not change, however far it turns. The
  // turns add up to ~20 rad, so every tangent passes opposite its start: without the
  // time-parallel update in step_accepted the transport from the start tangents degenerates and
  // this test fails (6 % energy error, checked by removing the call).
  System sys;
  std::vector<Index> ids;
  Rods& rods = helix_rod(sys, 9, ids);
  std::mt19937 rng(2024);
  perturb(sys, rng, 0.02);
  const double E0 = sys.potential_energy();
  REQUIRE(E0 > 0);
  std::normal_distribution<double> n(0, 1);
  std::uniform_real_distribution<double> turn(0.0, 0.1);
  double worst = 0;
  Vec3 axis = Vec3(n(rng), n(rng), n(rng)).normalized();
  for (int step = 0; step < 400; ++step) {
    // A steady turn (≈ 20 rad in all) about a slowly wandering axis.
    axis = (axis + 0.1 * Vec3(n(rng), n(rng), n(rng))).normalized();
    const Eigen::Matrix3d R = Eigen::AngleAxisd(turn(rng), axis).toRotationMatrix();
    const Vec3 shift(n(rng), n(rng), n(rng));
    for (Index i : ids) sys.nodes().set_position(i, R * sys.nodes().position(i) + 0.01 * shift);
    worst = std::max(worst, std::abs(sys.potential_energy() / E0 - 1));
    rods.step_accepted(sys.nodes().state());
  }
  MESSAGE("400 random rigid turns: largest relative energy change " << worst);
  CHECK(worst < 1e-8);
}

TEST_CASE("rods term: a term built alike and given history() continues bit for bit") {
  // A helix hanging from its first two vertices, swinging: θ, the time-parallel frames and the
  // reference twists all move on from step to step.
  struct Swing {
    System sys;
    std::vector<Index> ids;
    Rods* rods = nullptr;
    LinearlyImplicitEuler euler;
    Swing() {
      rods = &helix_rod(sys, 9, ids);
      sys.nodes().fix(ids[0]);
      sys.nodes().fix(ids[1]);
      sys.add<Gravity>(Vec3(0, 0, -9.81));
    }
    void run(int steps) {
      for (int s = 0; s < steps; ++s) (void)euler.step(sys, 2e-3);
    }
  };
  Swing a;
  a.run(30);
  Swing b, c;  // b takes a's whole state; c all but the rods'
  for (Swing* s : {&b, &c}) {
    std::copy(a.sys.nodes().x().begin(), a.sys.nodes().x().end(), s->sys.nodes().x().begin());
    std::copy(a.sys.nodes().v().begin(), a.sys.nodes().v().end(), s->sys.nodes().v().begin());
    s->euler.restore(s->sys, a.euler.history(a.sys));
  }
  const auto history = a.rods->history();
  REQUIRE(history.size() == 1);
  CHECK(history[0].rod.theta.size() == 8);
  CHECK(history[0].rod.reference_twist.size() == 7);
  b.rods->restore(history);
  a.run(30);
  b.run(30);
  c.run(30);
  const auto xa = a.sys.nodes().x(), xb = b.sys.nodes().x(), xc = c.sys.nodes().x();
  CHECK(std::equal(xa.begin(), xa.end(), xb.begin()));
  CHECK(a.rods->rod(0).theta()[4] == b.rods->rod(0).theta()[4]);
  CHECK_FALSE(std::equal(xa.begin(), xa.end(), xc.begin()));  // the rods' state matters

  // A history that does not fit is refused, the term unchanged.
  auto bad = history;
  bad[0].rod.director.pop_back();
  CHECK_THROWS_AS(b.rods->restore(bad), InputError);
  bad = history;
  bad[0].solved_at.push_back(0.0);
  CHECK_THROWS_AS(b.rods->restore(bad), InputError);
  bad = history;
  bad[0].rod.reference_twist[2] = std::nan("");
  CHECK_THROWS_AS(b.rods->restore(bad), InputError);
  CHECK_THROWS_AS(b.rods->restore({}), InputError);
  CHECK(a.rods->rod(0).theta()[4] == b.rods->rod(0).theta()[4]);
}

}  // namespace test_rods_term
