// Rods' twist angles as degrees of freedom of the System (Rods::use_angle_dofs), integrated by
// NewtonEuler: forces and torques are minus the gradient over positions and angles and the
// assembled Jacobian is its exact second derivative (finite differences); without inertia the
// angles reproduce the quasi-static rods; with inertia a twist oscillator follows backward
// Euler's exact recurrence; a rod twisted past π and back at a prescribed rate keeps the exact
// twist energy with no jump; integrators that cannot integrate angles refuse them; NewtonEuler
// tells the terms about every accepted step.
#include <cmath>
#include <limits>
#include <numbers>
#include <random>
#include <string>
#include <vector>

#include <Eigen/Dense>
#include <doctest/doctest.h>

#include "helpers.hpp"
#include "sewn/physics/errors.hpp"
#include "sewn/physics/integrate/newton_euler.hpp"
#include "sewn/physics/rods/rods_term.hpp"

namespace test_rod_angle_dofs {

using namespace sewn::physics;
using namespace sewn::physics::rods;

namespace angle_dofs_test {

// A straight rod of two 0.1 m edges along x, its three vertices fixed (only its angles move),
// circular section of radius r, E = 10 MPa, nu = 0.3.
Rods& fixed_two_edge_rod(System& sys, double r) {
  std::vector<Index> ids;
  for (int i = 0; i < 3; ++i) ids.push_back(sys.nodes().add(Vec3(0.1 * i, 0, 0), Vec3::Zero(), 1.0));
  for (Index i : ids) sys.nodes().fix(i);
  Rods& rods = sys.add<Rods>();
  (void)rods.add_rod(ids, sys.nodes().x(), false, Section::circular(1e7, 0.3, r));
  return rods;
}

// A hanging helical rod (natural curvature and twist), first two vertices and θ^0 clamped.
Rods& hanging_helix(System& sys, int n) {
  std::vector<Index> ids;
  for (int i = 0; i < n; ++i) {
    const double s = 0.5 * i;
    ids.push_back(sys.nodes().add(Vec3(0.2 * std::cos(s), 0.2 * std::sin(s), -0.04 * i), Vec3::Zero(), 0.002));
  }
  sys.nodes().fix(ids[0]);
  sys.nodes().fix(ids[1]);
  Rods& rods = sys.add<Rods>();
  (void)rods.add_rod(ids, sys.nodes().x(), false, Section::elliptic(2e6, 0.3, 0.006, 0.004));
  rods.rod(0).fix_theta(0);
  sys.add<Gravity>(Vec3(0, 0, -9.81));
  return rods;
}

// Flat arrays q = (positions, angles, padding) of the system's current state.
std::vector<double> flat_state(const System& sys) {
  std::vector<double> q(sys.nodes().x().begin(), sys.nodes().x().end());
  q.insert(q.end(), sys.angles().values().begin(), sys.angles().values().end());
  q.resize(3 * (std::size_t{sys.nodes().size()} + AngleLayout::blocks_for(sys.angles().size())), 0.0);
  return q;
}

StateView flat_view(const System& sys, const std::vector<double>& q, const std::vector<double>& v) {
  const std::size_t n3 = 3 * std::size_t{sys.nodes().size()}, na = sys.angles().size();
  return {std::span<const double>(q).first(n3), std::span<const double>(v).first(n3), sys.nodes().masses(),
          std::span<const double>(q).subspan(n3, na), std::span<const double>(v).subspan(n3, na)};
}

// Counts accepted steps.
class StepCounter final : public ForceTerm {
 public:
  [[nodiscard]] std::string_view name() const override { return "step counter"; }
  void add_forces(const StateView&, std::span<double>) const override {}
  [[nodiscard]] double potential_energy(const StateView&) const override { return 0; }
  void step_accepted(const StateView&) override { ++steps; }
  int steps = 0;
};



TEST_CASE("rod angle DOFs: torques and forces are minus the gradient, the Jacobian its second derivative") {
  System sys;
  Rods& rods = hanging_helix(sys, 7);
  rods.use_angle_dofs(sys.angles(), 1e-6);
  // The term keeps its default (project_hessians on): with angle DOFs it projects only when the
  // request asks (project_element_hessians), so an unprojected request gets the exact Jacobian
  // Newton's exact-first pass needs.
  std::mt19937 rng(16);
  std::normal_distribution<double> noise(0, 0.01);
  for (double& x : sys.nodes().x()) x += noise(rng);
  for (double& t : sys.angles().values()) t += 30 * noise(rng);
  const std::vector<double> q0 = flat_state(sys);
  const std::vector<double> zero(q0.size(), 0.0);
  const std::size_t n = 3 * std::size_t{sys.nodes().size()} + sys.angles().size();
  auto force = [&](const std::vector<double>& q) {
    std::vector<double> f(q.size(), 0.0);
    sys.add_forces(flat_view(sys, q, zero), f);
    return f;
  };
  auto energy = [&](const std::vector<double>& q) {
    double e = 0;
    for (const auto& t : sys.terms()) e += t->potential_energy(flat_view(sys, q, zero));
    return e;
  };
  const std::vector<double> f0 = force(q0);
  BlockMatrix& A = sys.matrix();
  A.set_zero();
  JacobianRequest req;
  req.matrix = &A;
  req.cx = 1.0;  // A = ∂F/∂q
  for (const auto& t : sys.terms()) t->add_jacobians(flat_view(sys, q0, zero), req);
  const Eigen::MatrixXd J = Eigen::MatrixXd(A.to_sparse());
  const double eps = 1e-6;
  double worst_f = 0, worst_j = 0, scale_f = 0, scale_j = 0;
  for (std::size_t k = 0; k < n; ++k) {
    std::vector<double> qp = q0, qm = q0;
    qp[k] += eps;
    qm[k] -= eps;
    worst_f = std::max(worst_f, std::abs(-(energy(qp) - energy(qm)) / (2 * eps) - f0[k]));
    scale_f = std::max(scale_f, std::abs(f0[k]));
    const std::vector<double> fp = force(qp), fm = force(qm);
    for (std::size_t r = 0; r < n; ++r) {
      const double fd = (fp[r] - fm[r]) / (2 * eps);
      worst_j = std::max(worst_j, std::abs(fd - J(static_cast<Eigen::Index>(r), static_cast<Eigen::Index>(k))));
      scale_j = std::max(scale_j, std::abs(fd));
    }
  }
  MESSAGE("angle DOFs: |f - fd| " << worst_f << " of " << scale_f << ", |J - fd| " << worst_j << " of " << scale_j);
  CHECK(scale_f > 1e-3);
  CHECK(worst_f < 1e-6 * scale_f);
  CHECK(worst_j < 1e-5 * scale_j);
  // Asked for the PSD stand-in, the term projects every stencil: −∂F/∂q is then PSD, where the
  // exact one of this strained helix is not (so the two requests really differ).
  req.options.project_element_hessians = true;
  A.set_zero();
  for (const auto& t : sys.terms()) t->add_jacobians(flat_view(sys, q0, zero), req);
  const Eigen::MatrixXd Jp = Eigen::MatrixXd(A.to_sparse());
  const double exact_min = Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd>(-J).eigenvalues().minCoeff();
  const double projected_min = Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd>(-Jp).eigenvalues().minCoeff();
  MESSAGE("smallest eigenvalue of -dF/dq: exact " << exact_min << ", projected " << projected_min);
  CHECK(exact_min < -1e-6 * scale_j);
  CHECK(projected_min > -1e-10 * scale_j);
  // An angle's torque is really there: the twist of the perturbed θ pushes back.
  double torque = 0;
  for (std::size_t a = 0; a < sys.angles().size(); ++a) torque = std::max(torque, std::abs(f0[3 * std::size_t{sys.nodes().size()} + a]));
  CHECK(torque > 1e-4);
}

TEST_CASE("rod angle DOFs without inertia follow the quasi-static rods under NewtonEuler") {
  System quasi, dofs, exact;
  (void)hanging_helix(quasi, 9);
  Rods& rods = hanging_helix(dofs, 9);
  rods.use_angle_dofs(dofs.angles(), 0.0);
  // the same with the stencils' full Hessians unprojected: the projection of the coupled
  // bend-twist Hessian is what slows Newton down here (docs/rods.md)
  Rods& exact_rods = hanging_helix(exact, 9);
  exact_rods.use_angle_dofs(exact.angles(), 0.0);
  exact_rods.set_project_hessians(false);
  integrate::NewtonEulerOptions opt;
  opt.velocity_tolerance = 1e-10;
  opt.solver = integrate::LinearSolver::ldlt;
  const std::vector<double> start(dofs.nodes().x().begin(), dofs.nodes().x().end());
  integrate::NewtonEuler a(opt), b(opt), c(opt);
  int iterations_quasi = 0, iterations_dofs = 0, iterations_exact = 0;
  for (int s = 0; s < 40; ++s) {
    iterations_quasi += a.step(quasi, 5e-3).iterations;
    iterations_dofs += b.step(dofs, 5e-3).iterations;
    iterations_exact += c.step(exact, 5e-3).iterations;
  }
  double diff = 0, moved = 0, diff_exact = 0;
  for (Index i = 0; i < quasi.nodes().size(); ++i) {
    diff = std::max(diff, (quasi.nodes().position(i) - dofs.nodes().position(i)).norm());
    diff_exact = std::max(diff_exact, (quasi.nodes().position(i) - exact.nodes().position(i)).norm());
    moved = std::max(moved, (dofs.nodes().position(i) - Vec3(start[3 * i], start[3 * i + 1], start[3 * i + 2])).norm());
  }
  double theta_diff = 0;
  for (int j = 0; j < rods.rod(0).num_edges(); ++j)
    theta_diff = std::max(theta_diff, std::abs(dofs.angles().values()[rods.angle_of(0, j)] -
                                               dynamic_cast<const Rods&>(*quasi.terms()[0]).rod(0).theta()[static_cast<std::size_t>(j)]));
  MESSAGE("40 steps: positions differ by " << diff << " m (moved " << moved << " m), angles by " << theta_diff
                                           << " rad; Newton iterations quasi-static " << iterations_quasi << ", angle DOFs "
                                           << iterations_dofs << ", angle DOFs with unprojected Hessians " << iterations_exact
                                           << " (positions differ by " << diff_exact << " m)");
  CHECK(moved > 0.01);
  CHECK(diff < 1e-8);
  CHECK(diff_exact < 1e-8);
  CHECK(theta_diff < 1e-6);
}

TEST_CASE("rod angle DOFs with inertia: a twist oscillator follows backward Euler's recurrence") {
  // Three fixed collinear vertices; θ^0 fixed, θ^1 free with inertia J: E = GJ/(2D)(θ^1)².
  System sys;
  Rods& rods = fixed_two_edge_rod(sys, 0.01);
  const Section sec = Section::circular(1e7, 0.3, 0.01);
  rods.rod(0).fix_theta(0);
  const double rho_polar = 1000 * std::numbers::pi * std::pow(0.01, 4) / 2;  // ρπr⁴/2
  rods.use_angle_dofs(sys.angles(), rho_polar);
  const Index a = rods.angle_of(0, 1);
  sys.angles().values()[a] = 0.3;
  const double J = rho_polar * 0.1, D = 0.1, w2 = sec.GJ / (D * J), h = 1e-4;
  integrate::NewtonEulerOptions opt;
  opt.velocity_tolerance = 1e-12;
  integrate::NewtonEuler newton(opt);
  double x = 0.3, v = 0, worst = 0;
  for (int s = 0; s < 30; ++s) {
    (void)newton.step(sys, h);
    const double x1 = (x + h * v) / (1 + h * h * w2);
    v = (x1 - x) / h;
    x = x1;
    worst = std::max(worst, std::abs(sys.angles().values()[a] - x) + h * std::abs(sys.angles().rates()[a] - v));
  }
  MESSAGE("twist oscillator: omega h = " << std::sqrt(w2) * h << ", theta after 30 steps " << x << ", worst error " << worst);
  CHECK(std::abs(x - 0.3) > 0.1);  // it moved
  CHECK(worst < 1e-9);
  CHECK(sys.kinetic_energy() > 0);
}

TEST_CASE("rod angle DOFs: Newton turns no angle by more than max_angle_step per iteration") {
  // Three fixed collinear vertices, θ^0 fixed, θ^1 free without inertia and twisted by 3 rad:
  // E = GJ/(2D)(θ^1)² is quadratic, so one Newton iteration would turn it back by 3 rad. The
  // trust region takes it there in steps of at most π/4: three limited ones, the rest, and
  // the converged check; the answer is the same.
  auto twisted = [](System& sys) {
    Rods& rods = fixed_two_edge_rod(sys, 0.01);
    rods.rod(0).fix_theta(0);
    rods.use_angle_dofs(sys.angles(), 0.0);
    sys.angles().values()[rods.angle_of(0, 1)] = 3.0;
    return rods.angle_of(0, 1);
  };
  System limited, free;
  const Index a = twisted(limited), b = twisted(free);
  integrate::NewtonEulerOptions opt;
  opt.velocity_tolerance = 1e-9;  // 1e-12 rad per step: above θ's round-off
  const integrate::NewtonReport r = integrate::NewtonEuler(opt).step(limited, 1e-3);
  opt.max_angle_step = std::numeric_limits<double>::infinity();
  const integrate::NewtonReport u = integrate::NewtonEuler(opt).step(free, 1e-3);
  MESSAGE("limited: " << r.iterations << " iterations, " << r.angle_step_limits << " limited; unlimited: " << u.iterations);
  CHECK(r.angle_step_limits == 3);
  CHECK(r.iterations == 5);
  CHECK(u.angle_step_limits == 0);
  CHECK(u.iterations == 2);
  CHECK(std::abs(limited.angles().values()[a]) < 1e-12);
  CHECK(std::abs(free.angles().values()[b]) < 1e-12);
  opt.max_angle_step = 0.0;
  CHECK_THROWS_WITH_AS((void)integrate::NewtonEuler(opt).step(limited, 1e-3), doctest::Contains("max_angle_step"), InputError);
}

TEST_CASE("rod angle DOFs: Newton's stopping test counts a twist update as the distance it moves the section") {
  // The twisted edge again (3 rad, no inertia, π/4 per iteration): rods give their angles the
  // section's radius of gyration r/√2 as length, so the first (limited) iteration moves the
  // section by r/√2 · π/4 = 5.55 mm; with h = 1 s and a tolerance of 10 mm/s that is converged,
  // where the π/4 rad of the same update read as metres would not be.
  System sys;
  const double r = 0.01;
  Rods& rods = fixed_two_edge_rod(sys, r);
  rods.rod(0).fix_theta(0);
  rods.use_angle_dofs(sys.angles(), 0.0);
  for (double l : sys.angles().lengths()) CHECK(l == doctest::Approx(r / std::sqrt(2.0)).epsilon(1e-14));
  sys.angles().values()[rods.angle_of(0, 1)] = 3.0;
  integrate::NewtonEulerOptions opt;
  opt.velocity_tolerance = 0.01;
  const integrate::NewtonReport rep = integrate::NewtonEuler(opt).step(sys, 1.0);
  CHECK(rep.iterations == 1);
  CHECK(rep.step_velocity == doctest::Approx(r / std::sqrt(2.0) * std::numbers::pi / 4).epsilon(1e-12));
  CHECK(sys.angles().values()[rods.angle_of(0, 1)] == doctest::Approx(3.0 - std::numbers::pi / 4).epsilon(1e-12));
  // The table's own checks: lengths default to 1 m and must be finite and > 0, one per angle.
  AngleTable t;
  const double v[2] = {0, 0}, bad[2] = {0.1, 0.0}, inf[2] = {0.1, std::numeric_limits<double>::infinity()};
  const unsigned char f[2] = {0, 0};
  (void)t.add("plain", v, v, f);
  CHECK(t.lengths().size() == 2);
  CHECK(t.lengths()[1] == 1.0);
  CHECK_THROWS_WITH_AS((void)t.add("zero", v, v, f, bad), doctest::Contains("length of angle 1"), InputError);
  CHECK_THROWS_WITH_AS((void)t.add("infinite", v, v, f, inf), doctest::Contains("length of angle 1"), InputError);
  CHECK_THROWS_WITH_AS((void)t.add("short", v, v, f, std::span<const double>(bad, 1)), doctest::Contains("1 lengths"), InputError);
}

TEST_CASE("rod angle DOFs: integrators that cannot integrate them refuse, NewtonEuler reports every accepted step") {
  System sys;
  Rods& rods = hanging_helix(sys, 5);
  rods.use_angle_dofs(sys.angles(), 1e-6);
  auto& counter = sys.add<StepCounter>();
  LinearlyImplicitEuler euler;
  CHECK_THROWS_WITH_AS((void)euler.step(sys, 1e-3), doctest::Contains("angle DOFs"), InputError);
  SymplecticEuler symplectic;
  CHECK_THROWS_AS((void)symplectic.step(sys, 1e-3), InputError);
  CHECK_THROWS_WITH_AS(rods.use_angle_dofs(sys.angles(), 1e-6), doctest::Contains("twice"), InputError);
  std::vector<Index> more{0, 1};
  CHECK_THROWS_WITH_AS((void)rods.add_rod(more, sys.nodes().x(), false, Section::circular(1e6, 0.3, 0.01)),
                       doctest::Contains("after use_angle_dofs"), InputError);
  integrate::NewtonEuler newton;
  for (int s = 0; s < 3; ++s) (void)newton.step(sys, 1e-3);
  CHECK(counter.steps == 3);
}

TEST_CASE("rod angle DOFs: a hanging rod twisted past pi and back under Newton, its iterations counted") {
  // The quasi-static case of test_rods_term under NewtonEuler with θ as DOFs: the top edge is
  // clamped, the bottom edge's angle is driven 0 → 3π → 0 at a prescribed rate (a fixed angle
  // follows its rate). The rod stays straight, so its elastic energy follows GJΦ²/(2 L_tw)
  // (plus the small stretch under its weight) with no jump at π or 2π, and returns to its start.
  const int n = 11;
  const double L = 0.5, r = 0.005, h = 1e-3;
  const Section sec = Section::circular(1e7, 0.3, r);
  System sys;
  Rods& rods = test::hanging_clamped_rod(sys, n, L, sec);
  const int last = n - 2;
  rods.use_angle_dofs(sys.angles(), 1000 * std::numbers::pi * std::pow(r, 4) / 2);  // ρπr⁴/2 per metre
  const Index driven = rods.angle_of(0, last);
  sys.add<Gravity>(Vec3(0, 0, -9.81));
  sys.add<MassDamping>(10.0);
  integrate::NewtonEulerOptions opt;
  opt.solver = integrate::LinearSolver::ldlt;
  integrate::NewtonEuler newton(opt);
  int iterations = 0, worst = 0, steps = 0;
  auto step = [&] {
    const int it = newton.step(sys, h).iterations;
    iterations += it;
    worst = std::max(worst, it);
    ++steps;
  };
  for (int s = 0; s < 300; ++s) step();  // settle under gravity
  const double E0 = sys.potential_energy(EnergyKind::internal);
  double Ltw = 0;
  for (int k = 0; k < rods.rod(0).num_stencils(); ++k) Ltw += rods.rod(0).stencil_rest(k).voronoi;
  const int ramp = 600;
  const double Phi_max = 3 * std::numbers::pi;
  double prev = E0, max_jump = 0;
  auto drive = [&](double rate) {
    sys.angles().rates()[driven] = rate;
    for (int k = 0; k < ramp; ++k) {
      step();
      const double E = sys.potential_energy(EnergyKind::internal);
      max_jump = std::max(max_jump, std::abs(E - prev));
      prev = E;
    }
    sys.angles().rates()[driven] = 0.0;
  };
  drive(Phi_max / (ramp * h));
  CHECK(sys.angles().values()[driven] == doctest::Approx(Phi_max).epsilon(1e-12));
  for (int s = 0; s < 200; ++s) step();  // let it settle at the peak
  const double at_peak = sys.potential_energy(EnergyKind::internal) - E0;
  prev = sys.potential_energy(EnergyKind::internal);
  drive(-Phi_max / (ramp * h));
  for (int s = 0; s < 300; ++s) step();
  const double twist = sec.GJ * Phi_max * Phi_max / (2 * Ltw);
  MESSAGE("Newton, hanging rod twisted by 3 pi and back: energy gained " << at_peak << " J, GJ Phi^2/(2 L_tw) " << twist
                                                                         << " J; largest change in one step " << max_jump
                                                                         << " J; " << iterations << " Newton iterations in "
                                                                         << steps << " steps (worst " << worst << ")");
  CHECK(at_peak == doctest::Approx(twist).epsilon(1e-3));
  CHECK(max_jump < 0.02 * twist);  // ~ twist · 2·(1/600): smooth, no jump
  CHECK(std::abs(sys.angles().values()[driven]) < 1e-12);
  CHECK(sys.potential_energy(EnergyKind::internal) == doctest::Approx(E0).epsilon(1e-6));
}

}  // namespace angle_dofs_test

}  // namespace test_rod_angle_dofs
