// Elastic models against exact answers (PHYSICS_NOTES §4) and backward Euler by Newton:
// StVK and CST uniaxial stretch (exact for any mesh), cylindrical bending of a hinge shell
// with k_B = D/6 (ratio converging to 1), backward Euler's exact discrete decay on a linear
// oscillator (undamped and mass-damped), a spinning body without strain, an inverted
// tetrahedron that recovers with the stable neo-Hookean law (and stays inverted with StVK),
// steps 100× the explicit limit, a stiffness contrast of 1e6 (which once stalled Newton on the
// round-off of the stiff elements' energies), and failure reports that leave the state unchanged.
#include <doctest/doctest.h>

#include <cmath>
#include <limits>
#include <numbers>
#include <random>
#include <vector>

#include "../../bench/elastic/tet_cantilever.hpp"
#include "elastic_helpers.hpp"
#include "helpers.hpp"
#include "sewn/physics/integrate/newton_euler.hpp"
#include "sewn/physics/shells/shell_terms.hpp"
#include "sewn/physics/solve/linear_solver.hpp"
#include "sewn/physics/solids/tets.hpp"

namespace test_elastic_models {

using namespace sewn::physics;
using namespace sewn::physics::test;
using doctest::Approx;
using Eigen::Matrix3d;
using Eigen::Vector3d;
using integrate::NewtonEuler;
using integrate::NewtonEulerOptions;

namespace {

// Newton's linear solvers this build has: the kept-factorization PCG needs CHOLMOD.
std::vector<integrate::LinearSolver> newton_solvers() {
  std::vector<integrate::LinearSolver> v{integrate::LinearSolver::ldlt, integrate::LinearSolver::cg};
  if (solve::available(solve::Backend::cholmod_pcg)) v.push_back(integrate::LinearSolver::cholmod_pcg);
  return v;
}

const char* solver_name(integrate::LinearSolver s) {
  return s == integrate::LinearSolver::cg ? "cg" : s == integrate::LinearSolver::ldlt ? "ldlt" : "cholmod-pcg";
}

double total_energy(System& sys) { return sys.kinetic_energy() + sys.potential_energy(); }

// E = μ(3λ+2μ)/(λ+μ), ν = λ/(2(λ+μ)) for the notes' μ = 0.7, λ = 1.3.
constexpr double notes_E = 0.7 * (3 * 1.3 + 2 * 0.7) / (1.3 + 0.7), notes_nu = 1.3 / (2 * (1.3 + 0.7));

}  // namespace

TEST_CASE("StVK tetrahedra, uniaxial stretch: exact lateral stretch, stress and energy on any tet mesh") {
  const double s = 1.2, L = 1.5, W = 1.0, H = 0.8;
  const double r = std::sqrt(1.0 - notes_nu * (s * s - 1.0));
  const double P11 = notes_E * s * (s * s - 1.0) / 2.0;
  CHECK(P11 == Approx(0.48972).epsilon(1e-5));  // the notes' number
  System sys;
  const TetMesh box = kuhn_box(3, 2, 2, L, W, H);
  add_tets(sys, box, solids::TetLaw::stvk, notes_E, notes_nu, 1.0);
  SUBCASE("the homogeneous state is an equilibrium with the exact end load") {
    for (Index i = 0; i < sys.nodes().size(); ++i) sys.nodes().set_position(i, Vector3d(s, r, r).asDiagonal() * box.x[i]);
    const Eigen::VectorXd f = forces(sys);
    double end0 = 0.0, endL = 0.0, other = 0.0;
    for (Index i = 0; i < sys.nodes().size(); ++i) {
      const Vector3d fi = f.segment<3>(3 * i);
      const double X = box.x[i].x();
      if (X == 0.0) end0 += fi.x();
      if (X == L) endL += fi.x();
      const bool on_end = X == 0.0 || X == L;
      other = std::max(other, on_end ? fi.tail<2>().cwiseAbs().maxCoeff() : fi.cwiseAbs().maxCoeff());
    }
    CHECK(endL == Approx(-P11 * W * H).epsilon(1e-12));
    CHECK(end0 == Approx(P11 * W * H).epsilon(1e-12));
    CHECK(other < 1e-13 * P11 * W * H);
    const double psi = notes_E / 2.0 * std::pow((s * s - 1.0) / 2.0, 2);
    CHECK(sys.potential_energy() == Approx(psi * L * W * H).epsilon(1e-12));
  }
  SUBCASE("Newton finds it from rest with the end displaced on rollers (quasi-static step)") {
    const double h = 1e4;
    for (Index i = 0; i < sys.nodes().size(); ++i) {
      const Vector3d X = box.x[i];
      if (X.x() == 0.0 || X.x() == L) sys.nodes().fix(i, axis_x);
      if (X.x() == L) sys.nodes().set_position(i, Vector3d(s * L, X.y(), X.z()));
      if (X.x() == 0.0 && X.y() == 0.0) sys.nodes().fix(i, axis_y);
      if (X.x() == 0.0 && X.y() == 0.0 && X.z() == 0.0) sys.nodes().fix(i, axis_z);
      if (X.x() == 0.0 && X.y() == W && X.z() == 0.0) sys.nodes().fix(i, axis_z);
    }
    NewtonEulerOptions opt;
    opt.velocity_tolerance = 1e-12 / h;
    const std::vector<double> start(sys.nodes().x().begin(), sys.nodes().x().end());
    for (const auto solver : newton_solvers()) {
      std::copy(start.begin(), start.end(), sys.nodes().x().begin());
      for (Index i = 0; i < sys.nodes().size(); ++i) sys.nodes().set_velocity(i, Vector3d::Zero());
      opt.solver = solver;
      opt.cg_tolerance = 1e-10;
      NewtonEuler newton(opt);
      const auto rep = newton.step(sys, h);
      MESSAGE("StVK uniaxial s = 1.2, quasi-static: " << rep.iterations << " Newton iterations, "
                                                         << rep.line_search_steps << " halvings, "
                                                         << rep.linear_iterations << " CG iterations ("
                                                         << solver_name(solver) << ")");
      double err = 0.0;
      for (Index i = 0; i < sys.nodes().size(); ++i) {
        const Vector3d X = box.x[i];
        err = std::max(err, (sys.nodes().position(i) - Vector3d(s * X.x(), r * X.y(), r * X.z())).cwiseAbs().maxCoeff());
      }
      CHECK(err < 1e-9);
    }
  }
}

TEST_CASE("CST membrane, uniaxial stretch: exact lateral stretch, stress and energy on any triangulation") {
  const double E = 3.0, nu = 0.3, t = 0.02, s = 1.3, L = 2.0, W = 1.0;
  const double r = std::sqrt(1.0 - nu * (s * s - 1.0));
  const double P11 = s * E * (s * s - 1.0) / 2.0;
  for (const bool alternate : {false, true}) {
    System sys;
    const TriMesh m = tri_rectangle(4, 3, L, W, alternate);
    for (const auto& p : m.x) sys.nodes().add(Vector3d(s * p.x(), r * p.y(), 0.0), Vector3d::Zero(), 1.0);
    auto& mem = sys.add<shells::Membranes>();
    for (const auto& tri : m.tris) {
      shells::TriPositions X;
      for (int a = 0; a < 3; ++a) X.col(a) = m.x[tri[a]];
      mem.add(tri, X, E, nu, t);
    }
    const Eigen::VectorXd f = forces(sys);
    double endL = 0.0, other = 0.0;
    for (Index i = 0; i < sys.nodes().size(); ++i) {
      const Vector3d fi = f.segment<3>(3 * i);
      const bool on_end = m.x[i].x() == 0.0 || m.x[i].x() == L;
      if (m.x[i].x() == L) endL += fi.x();
      other = std::max(other, on_end ? fi.tail<2>().cwiseAbs().maxCoeff() : fi.cwiseAbs().maxCoeff());
    }
    CHECK(endL == Approx(-P11 * t * W).epsilon(1e-12));
    CHECK(other < 1e-13 * P11 * t * W);
    CHECK(sys.potential_energy() == Approx(t * L * W * E / 2.0 * std::pow((s * s - 1.0) / 2.0, 2)).epsilon(1e-12));
  }
}

TEST_CASE("hinge shell bent into a cylinder: energy / (½ D A / R²) converges to 1 with k_B = D/6") {
  const double E = 1e6, nu = 0.3, t = 1e-3, L = 1.0, W = 0.5, R = 0.8;
  const double D = E * t * t * t / (12.0 * (1.0 - nu * nu));
  const double kb = shells::hinge_stiffness(E, nu, t);
  CHECK(kb == Approx(D / 6.0));
  for (const bool alternate : {false, true}) {
    double last_err = 1.0;
    for (const int n : {4, 8, 16, 32}) {
      const TriMesh m = tri_rectangle(2 * n, n, L, W, alternate);
      System sys;
      std::vector<double> rest;
      for (const auto& p : m.x) {
        sys.nodes().add(Vector3d(R * std::sin(p.x() / R), p.y(), R * (1.0 - std::cos(p.x() / R))), Vector3d::Zero(), 1.0);
        rest.insert(rest.end(), {p.x(), p.y(), p.z()});
      }
      std::vector<std::array<Index, 3>> tris(m.tris.begin(), m.tris.end());
      sys.add<shells::Hinges>().add_interior_edges(tris, rest, kb);
      const double ratio = sys.potential_energy() / (0.5 * D * L * W / (R * R));
      const double err = std::abs(ratio - 1.0);
      const double order = std::log2(last_err / err);
      MESSAGE("cylinder bending, " << std::string(alternate ? "alternating" : "parallel") << " diagonals, n = " << n
                                   << ": ratio " << ratio << ", observed order " << order);
      // First order: the edges on the free boundary carry no hinge, a strip of width ~1/n.
      if (n > 4) CHECK(order == Approx(1.0).epsilon(0.1));
      last_err = err;
    }
    CHECK(last_err < 1.0 / 32.0);
  }
}

TEST_CASE("Newton backward Euler, linear oscillator: the exact discrete decay, undamped and mass-damped") {
  const double k = 250.0, m = 0.4, l = 0.3, omega = std::sqrt(k / m), h = 0.6 / omega;
  for (const auto solver : newton_solvers()) {
    CAPTURE(solver_name(solver));
    for (const double c : {0.0, 3.0}) {
      CAPTURE(c);
      System sys;
      sys.nodes().add({0, 0, 0}, {0, 0, 0}, 1.0);
      sys.nodes().fix(0);
      sys.nodes().add({l + 0.05, 0, 0}, {0.3, 0, 0}, m);
      sys.add<Springs>().add(0, 1, k, l);
      if (c > 0.0) sys.add<MassDamping>(c);
      NewtonEulerOptions opt;
      opt.solver = solver;
      opt.velocity_tolerance = 1e-12;
      opt.cg_tolerance = 1e-12;
      NewtonEuler newton(opt);
      // The exact recurrence: v' (1 + hc + h²ω²) = v - hω² x, x' = x + h v' (x from rest length).
      double x = 0.05, v = 0.3;
      int iterations = 0;
      for (int n = 0; n < 50; ++n) {
        iterations += newton.step(sys, h).iterations;
        v = (v - h * omega * omega * x) / (1.0 + h * c + h * h * omega * omega);
        x += h * v;
      }
      CHECK(sys.nodes().position(1).x() - l == Approx(x).epsilon(1e-9).scale(1e-14));
      CHECK(sys.nodes().velocity(1).x() == Approx(v).epsilon(1e-9).scale(1e-14));
      if (c == 0.0) {
        const double d = sys.nodes().position(1).x() - l;
        const double ratio = (0.5 * m * std::pow(sys.nodes().velocity(1).x(), 2) + 0.5 * k * d * d) /
                             (0.5 * m * 0.09 + 0.5 * k * 0.0025);
        CHECK(ratio == Approx(std::pow(1 + 0.36, -50)).epsilon(1e-8));
      }
      MESSAGE("linear oscillator, c = " << c << ": " << iterations << " Newton iterations in 50 steps");
    }
  }
}

TEST_CASE("a body spun at 10 rad/s develops no strain beyond the centrifugal one") {
  const double E = 1e6, rho = 1000.0, a = 0.2, omega = 10.0;
  const TetMesh box = kuhn_box(2, 2, 2, a, a, a);
  for (const auto law : {solids::TetLaw::stvk, solids::TetLaw::stable_neo_hookean}) {
    System sys;
    auto& tets = add_tets(sys, box, law, E, 0.3, rho);
    const Vector3d c(a / 2, a / 2, a / 2), axis = Vector3d(1, 2, 2).normalized();
    // Rigidly rotated to any angle: no energy, no force (Green strain).
    for (const double angle : {0.5, 2.0, 10.0}) {
      const Matrix3d Q = Eigen::AngleAxisd(angle, axis).toRotationMatrix();
      for (Index i = 0; i < sys.nodes().size(); ++i) sys.nodes().set_position(i, c + Q * (box.x[i] - c));
      // Round-off only: the stable neo-Hookean energy sums terms of size (λ+μ)V per element.
      const solids::Lame lm = solids::lame_from_young(E, 0.3);
      CHECK(sys.potential_energy() < 100 * std::numeric_limits<double>::epsilon() * (lm.lambda + lm.mu) * a * a * a);
      CHECK(forces(sys).cwiseAbs().maxCoeff() < 1e-10 * E * a * a);
    }
    for (Index i = 0; i < sys.nodes().size(); ++i) {
      sys.nodes().set_position(i, box.x[i]);
      sys.nodes().set_velocity(i, omega * axis.cross(box.x[i] - c));
    }
    // Dynamically, for 1 s (10 rad), the strain stays of the centrifugal order ρω²R²/E.
    NewtonEuler newton;
    double max_strain = 0.0;
    int iterations = 0;
    for (int n = 0; n < 200; ++n) {
      iterations += newton.step(sys, 5e-3).iterations;
      for (Index e = 0; e < tets.size(); ++e) {
        const Matrix3d F = solids::deformation_gradient(tets.gather(sys.nodes().state(), e), tets.rest(e));
        max_strain = std::max(max_strain, (0.5 * (F.transpose() * F - Matrix3d::Identity())).cwiseAbs().maxCoeff());
      }
    }
    const double centrifugal = rho * omega * omega * a * a / E;  // 4e-3
    MESSAGE("spin 10 rad/s for 10 rad: max Green strain " << max_strain << " (centrifugal scale " << centrifugal << "), "
                                                          << iterations << " Newton iterations in 200 steps");
    CHECK(max_strain < centrifugal);
  }
}

TEST_CASE("an inverted tetrahedron recovers with the stable neo-Hookean law; StVK leaves it inverted") {
  for (const auto law : {solids::TetLaw::stvk, solids::TetLaw::stable_neo_hookean}) {
    System sys;
    TetMesh one;
    one.x = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
    one.tets = {{0, 1, 2, 3}};
    auto& tets = add_tets(sys, one, law, 1e3, 0.3, 100.0);
    for (Index i = 0; i < 3; ++i) sys.nodes().fix(i);
    sys.add<MassDamping>(5.0);
    sys.nodes().set_position(3, {0, 0, -1});  // mirrored through the fixed face: F a reflection
    NewtonEuler newton;
    int iterations = 0;
    double first_positive = -1.0;
    for (int n = 0; n < 300; ++n) {
      iterations += newton.step(sys, 1e-2).iterations;
      const double Jn = solids::deformation_gradient(tets.gather(sys.nodes().state(), 0), tets.rest(0)).determinant();
      if (first_positive < 0.0 && Jn > 0.0) first_positive = (n + 1) * 1e-2;
    }
    const double J = solids::deformation_gradient(tets.gather(sys.nodes().state(), 0), tets.rest(0)).determinant();
    MESSAGE(std::string(law == solids::TetLaw::stvk ? "StVK" : "stable neo-Hookean")
            << ": det F = " << J << " after 3 s (first positive at t = " << first_positive << " s), " << iterations
            << " Newton iterations in 300 steps");
    if (law == solids::TetLaw::stvk) {
      CHECK(J == Approx(-1.0));  // the reflection is a zero-energy equilibrium
    } else {
      CHECK(first_positive > 0.0);
      CHECK(J == Approx(1.0).epsilon(1e-3));
    }
  }
}

TEST_CASE("Newton backward Euler at 100× the explicit limit: bounded, energy non-increasing; explicit refuses") {
  System sys;
  const TetMesh beam = kuhn_box(8, 2, 2, 1.0, 0.125, 0.125);
  const double E = 1e8, rho = 1000.0, b = 0.125;
  add_tets(sys, beam, solids::TetLaw::stvk, E, 0.3, rho);
  for (Index i = 0; i < sys.nodes().size(); ++i)
    if (beam.x[i].x() == 0.0) sys.nodes().fix(i);
  sys.add<Gravity>(Vector3d(0, 0, -9.81));
  const double h_explicit = sys.stable_step().h_max;
  REQUIRE(std::isfinite(h_explicit));
  const double h = 100.0 * h_explicit;
  CHECK_THROWS_AS(SymplecticEuler().step(sys, h), StabilityError);
  NewtonEuler newton;
  double e_prev = total_energy(sys);
  int worst = 0, total = 0;
  for (int n = 0; n < 30; ++n) {
    const auto rep = newton.step(sys, h);
    worst = std::max(worst, rep.iterations);
    total += rep.iterations;
    const double e = total_energy(sys);
    CHECK(e <= e_prev + 1e-12 * std::abs(e_prev));
    e_prev = e;
  }
  double tip = 0.0;
  for (Index i = 0; i < sys.nodes().size(); ++i) tip = std::min(tip, sys.nodes().position(i).z() - beam.x[i].z());
  MESSAGE("cantilever at h = " << h << " s (100x the bound " << h_explicit << " s): Newton iterations per step "
                               << total / 30.0 << " mean, " << worst << " worst; lowest tip displacement " << tip);
  // A load applied suddenly to an undamped linear system deflects it at most twice the static
  // sag (Euler-Bernoulli δ = qL⁴/8EI); backward Euler only dissipates, and linear tets are stiffer.
  const double sag = rho * 9.81 * b * b / (8.0 * E * b * b * b * b / 12.0);
  CHECK(tip < 0.0);
  CHECK(tip > -2.0 * sag);
}

TEST_CASE("mass-spring lattices step with Newton too, and CG and LDLT agree") {
  auto build = [](System& sys) {
    BoxLatticeSpec s;
    s.nx = 6;
    s.ny = s.nz = 2;
    s.lx = s.ly = s.lz = 0.1;
    s.E = 1e6;
    s.rho = 1000;
    const BoxLattice lat = build_box_lattice(sys, s);
    for (Index j = 0; j <= 2; ++j)
      for (Index k = 0; k <= 2; ++k) sys.nodes().fix(lat.node(0, j, k));
    sys.add<Gravity>(Vector3d(0, 0, -9.81));
  };
  System a, b;
  build(a);
  build(b);
  const double h = 20.0 * a.stable_step().h_max;
  NewtonEulerOptions oa, ob;
  oa.solver = integrate::LinearSolver::cg;
  oa.cg_tolerance = 1e-10;
  oa.velocity_tolerance = 1e-10;
  ob.solver = integrate::LinearSolver::ldlt;
  ob.velocity_tolerance = 1e-10;
  NewtonEuler na(oa), nb(ob);
  double e_prev = total_energy(a);
  for (int n = 0; n < 20; ++n) {
    (void)na.step(a, h);
    (void)nb.step(b, h);
    const double e = total_energy(a);
    CHECK(e <= e_prev + 1e-12 * std::abs(e_prev));
    e_prev = e;
  }
  double diff = 0.0, sag = 0.0;
  for (Index i = 0; i < a.nodes().size(); ++i) {
    diff = std::max(diff, (a.nodes().position(i) - b.nodes().position(i)).cwiseAbs().maxCoeff());
    sag = std::max(sag, -a.nodes().velocity(i).z() * h);
  }
  CHECK(sag > 0.0);  // it moved
  CHECK(diff < 1e-8);
}

TEST_CASE("Newton failures are reported with what failed and leave the state unchanged") {
  System sys;
  const TetMesh beam = kuhn_box(4, 1, 1, 1.0, 0.25, 0.25);
  add_tets(sys, beam, solids::TetLaw::stable_neo_hookean, 1e5, 0.3, 1000.0);
  for (Index i = 0; i < sys.nodes().size(); ++i)
    if (beam.x[i].x() == 0.0) sys.nodes().fix(i);
  sys.add<Gravity>(Vector3d(0, 0, -9.81));
  const std::vector<double> x0(sys.nodes().x().begin(), sys.nodes().x().end());
  auto unchanged = [&] {
    for (std::size_t k = 0; k < x0.size(); ++k)
      if (sys.nodes().x()[k] != x0[k] || sys.nodes().v()[k] != 0.0) return false;
    return true;
  };
  NewtonEulerOptions opt;
  opt.max_iterations = 1;
  opt.velocity_tolerance = 1e-14;
  NewtonEuler newton(opt);
  try {
    (void)newton.step(sys, 0.5);
    FAIL("expected a NewtonError");
  } catch (const integrate::NewtonError& e) {
    CHECK(e.reason() == integrate::NewtonError::too_many_iterations);
    CHECK(std::string(e.what()).find("no convergence") != std::string::npos);
    CHECK(e.report().iterations == 1);
  }
  CHECK(unchanged());
  CHECK_THROWS_AS((void)newton.step(sys, 0.0), InputError);
  CHECK_THROWS_AS((void)newton.step(sys, std::nan("")), InputError);
  sys.nodes().v()[7] = std::nan("");
  try {
    (void)newton.step(sys, 1e-3);
    FAIL("expected a NewtonError");
  } catch (const integrate::NewtonError& e) {
    CHECK(e.reason() == integrate::NewtonError::non_finite);
    CHECK(std::string(e.what()).find("node 2") != std::string::npos);
  }
  CHECK(std::isnan(sys.nodes().v()[7]));
}

TEST_CASE("stiffness contrast 1e6 in one solid: Newton converges with CG and LDLT alike, energy non-increasing") {
  const TetMesh bar = kuhn_box(6, 1, 1, 0.6, 0.1, 0.1);
  auto build = [&](System& sys) {
    for (const auto& p : bar.x) sys.nodes().add(p, Vector3d::Zero(), 0.1);
    auto& tets = sys.add<solids::Tets>(solids::TetLaw::stable_neo_hookean);
    for (const auto& t : bar.tets) {
      solids::TetPositions X;
      for (int a = 0; a < 4; ++a) X.col(a) = bar.x[t[a]];
      const double centroid_x = X.row(0).mean();
      tets.add(t, X, centroid_x < 0.3 ? 1e11 : 1e5, 0.3);  // steel-like next to a soft gel
    }
    for (Index i = 0; i < sys.nodes().size(); ++i)
      if (bar.x[i].x() == 0.0) sys.nodes().fix(i);
    sys.add<Gravity>(Vector3d(0, 0, -9.81));
  };
  System a, b;
  build(a);
  build(b);
  NewtonEulerOptions oa, ob;
  oa.solver = integrate::LinearSolver::cg;
  oa.cg_tolerance = 1e-8;
  oa.cg_max_iterations = 100000;
  ob.solver = integrate::LinearSolver::ldlt;
  NewtonEuler na(oa), nb(ob);
  double e_prev = total_energy(a);
  int newton = 0, cg = 0;
  for (int n = 0; n < 20; ++n) {
    const auto ra = na.step(a, 1e-2);
    (void)nb.step(b, 1e-2);
    newton += ra.iterations;
    cg += ra.linear_iterations;
    const double e = total_energy(a);
    CHECK(e <= e_prev + 1e-12 * std::abs(e_prev));
    e_prev = e;
  }
  double diff = 0.0, moved = 0.0;
  for (Index i = 0; i < a.nodes().size(); ++i) {
    diff = std::max(diff, (a.nodes().position(i) - b.nodes().position(i)).norm());
    moved = std::max(moved, (a.nodes().position(i) - bar.x[i]).norm());
  }
  MESSAGE("stiffness contrast 1e6: " << newton << " Newton iterations and " << cg << " CG iterations in 20 steps; "
                                     << "largest displacement " << moved << " m, CG vs LDLT " << diff << " m");
  CHECK(moved > 1e-3);           // the soft half sags
  CHECK(diff < 1e-6 * moved);    // both solvers find the same states
}

TEST_CASE("StVK tet cantilever: linear FE's tips at small sizes, the error against Timoshenko falling at a rising order") {
  // Linear tets lock in bending: before the asymptotic range the order rises towards 2. At a
  // strain of 1e-4 StVK must give linear FE's tips (PHYSICS_NOTES §4: 7.49 mm at N = 2, 11.67
  // at N = 4, same meshes) to about 0.1 %.
  std::vector<double> tip, err;
  for (int n : {1, 2, 4}) {
    sewn::tet_cantilever::Beam beam;
    sewn::tet_cantilever::build(beam, n);
    NewtonEulerOptions opt;
    opt.solver = integrate::LinearSolver::ldlt;
    const double h = 1e3;  // quasi-static: inertia ~1e-9 of the stiffness
    opt.velocity_tolerance = 1e-9 / h;
    NewtonEuler newton(opt);
    (void)newton.step(beam.sys, h);
    tip.push_back(sewn::tet_cantilever::tip_mm(beam));
    err.push_back(std::abs(tip.back() - sewn::tet_cantilever::timoshenko_mm) / sewn::tet_cantilever::timoshenko_mm);
  }
  CHECK(tip[1] == Approx(7.49).epsilon(2e-3));
  CHECK(tip[2] == Approx(11.67).epsilon(2e-3));
  const double order1 = std::log2(err[0] / err[1]), order2 = std::log2(err[1] / err[2]);
  MESSAGE("StVK tets: tip " << tip[0] << ", " << tip[1] << ", " << tip[2] << " mm; orders " << order1 << ", " << order2);
  CHECK(order1 > 0.0);
  CHECK(order2 > order1);
}

}  // namespace test_elastic_models
