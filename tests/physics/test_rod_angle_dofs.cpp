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

// Forces and torques, and the energy, at flat state q with zero velocities.
std::vector<double> forces_at(const System& sys, const std::vector<double>& q) {
  const std::vector<double> zero(q.size(), 0.0);
  std::vector<double> f(q.size(), 0.0);
  sys.add_forces(flat_view(sys, q, zero), f);
  return f;
}

double energy_at(const System& sys, const std::vector<double>& q) {
  const std::vector<double> zero(q.size(), 0.0);
  double e = 0;
  for (const auto& t : sys.terms()) e += t->potential_energy(flat_view(sys, q, zero));
  return e;
}

// Central differences at q0 along DOF k: the energy's derivative, the forces on either side.
struct CentralDifference {
  double energy;
  std::vector<double> plus, minus;
};
CentralDifference central_difference(const System& sys, const std::vector<double>& q0, std::size_t k, double eps) {
  std::vector<double> qp = q0, qm = q0;
  qp[k] += eps;
  qm[k] -= eps;
  return {(energy_at(sys, qp) - energy_at(sys, qm)) / (2 * eps), forces_at(sys, qp), forces_at(sys, qm)};
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
  const std::vector<double> f0 = forces_at(sys, q0);
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
    const CentralDifference d = central_difference(sys, q0, k, eps);
    worst_f = std::max(worst_f, std::abs(-d.energy - f0[k]));
    scale_f = std::max(scale_f, std::abs(f0[k]));
    const std::vector<double>& fp = d.plus, &fm = d.minus;
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
  // The product pass (∂F/∂q·v without the matrix) is the same Jacobian.
  Eigen::VectorXd v(J.cols()), Jv = Eigen::VectorXd::Zero(J.cols());
  for (Eigen::Index k = 0; k < v.size(); ++k) v[k] = noise(rng);
  JacobianRequest product;
  product.product_in = std::span<const double>(v.data(), static_cast<std::size_t>(v.size()));
  product.product_out = std::span<double>(Jv.data(), static_cast<std::size_t>(Jv.size()));
  for (const auto& t : sys.terms()) t->add_jacobians(flat_view(sys, q0, zero), product);
  CHECK((Jv - J * v).norm() <= 1e-12 * (J * v).norm());
  CHECK((J * v).norm() > 0);
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

// ---- condensed twist (Rods::condense_twist): θ stays quasi-static, and its rows in the Newton
// system make the position step the exact Newton step of the reduced energy min_θ E. The forces
// are minus the reduced energy's gradient and the Schur complement of the assembled matrix over
// the condensed angles is its Hessian (finite differences of the re-solved state); under
// NewtonEuler the condensed rods follow the quasi-static ones (−H_xx) to the solve's tolerance in
// fewer iterations; a rod that turns freely (singular θ block) is still solved; the integrator
// never moves a condensed angle itself.

// Total Newton iterations of `steps` steps of 5 ms.
int run(System& sys, int steps, double tolerance) {
  integrate::NewtonEulerOptions opt;
  opt.velocity_tolerance = tolerance;
  opt.solver = integrate::LinearSolver::ldlt;
  opt.max_iterations = 100;
  integrate::NewtonEuler newton(opt);
  int iterations = 0;
  for (int s = 0; s < steps; ++s) iterations += newton.step(sys, 5e-3).iterations;
  return iterations;
}

double largest_difference(const System& a, const System& b) {
  double d = 0;
  for (Index i = 0; i < a.nodes().size(); ++i) d = std::max(d, (a.nodes().position(i) - b.nodes().position(i)).norm());
  return d;
}

// Checks at the system's (perturbed) state that the forces are minus the gradient of the
// reduced energy over the positions and the integrated angles, and that the Schur complement
// of the assembled matrix over the condensed angles is its Hessian (central differences, each
// evaluation solving the condensed angles again).
void check_reduced_derivatives(System& sys) {
  std::vector<double> q0 = flat_state(sys);
  const std::vector<double> zero(q0.size(), 0.0);
  const std::size_t n3 = 3 * std::size_t{sys.nodes().size()};
  const std::vector<double> f0 = forces_at(sys, q0);
  // kept: positions and integrated angles; condensed: the solved ones, whose torques vanish
  std::vector<Eigen::Index> kept, theta;
  for (std::size_t k = 0; k < n3; ++k) kept.push_back(static_cast<Eigen::Index>(k));
  double torque = 0;
  for (std::size_t a = 0; a < sys.angles().size(); ++a) {
    const auto id = static_cast<Index>(a);
    if (sys.angles().fixed(id)) continue;
    (sys.angles().condensed(id) ? theta : kept).push_back(static_cast<Eigen::Index>(n3 + a));
    if (sys.angles().condensed(id)) torque = std::max(torque, std::abs(f0[n3 + a]));
  }
  BlockMatrix& A = sys.matrix();
  A.set_zero();
  JacobianRequest req;
  req.matrix = &A;
  req.cx = -1.0;  // A = −∂F/∂q = the Hessian over (x, θ) at the solved θ
  for (const auto& t : sys.terms()) t->add_jacobians(flat_view(sys, q0, zero), req);
  const Eigen::MatrixXd K = Eigen::MatrixXd(A.to_sparse());
  const auto nk = static_cast<Eigen::Index>(kept.size()), nt = static_cast<Eigen::Index>(theta.size());
  auto pick = [&](const std::vector<Eigen::Index>& rows, const std::vector<Eigen::Index>& cols) {
    Eigen::MatrixXd M(static_cast<Eigen::Index>(rows.size()), static_cast<Eigen::Index>(cols.size()));
    for (std::size_t r = 0; r < rows.size(); ++r)
      for (std::size_t c = 0; c < cols.size(); ++c) M(static_cast<Eigen::Index>(r), static_cast<Eigen::Index>(c)) = K(rows[r], cols[c]);
    return M;
  };
  const Eigen::MatrixXd Kkk = pick(kept, kept), Kkt = pick(kept, theta);
  const Eigen::MatrixXd schur = Kkk - Kkt * pick(theta, theta).ldlt().solve(Kkt.transpose());
  REQUIRE(nt > 0);
  const double eps = 1e-6;
  double worst_f = 0, scale_f = 0, worst_h = 0, scale_h = 0, dropped = 0;
  for (Eigen::Index c = 0; c < nk; ++c) {
    const auto k = static_cast<std::size_t>(kept[static_cast<std::size_t>(c)]);
    const CentralDifference d = central_difference(sys, q0, k, eps);
    worst_f = std::max(worst_f, std::abs(-d.energy - f0[k]));
    scale_f = std::max(scale_f, std::abs(f0[k]));
    const std::vector<double>& fp = d.plus, &fm = d.minus;
    for (Eigen::Index r = 0; r < nk; ++r) {
      const auto kr = static_cast<std::size_t>(kept[static_cast<std::size_t>(r)]);
      const double fd = -(fp[kr] - fm[kr]) / (2 * eps);
      worst_h = std::max(worst_h, std::abs(fd - schur(r, c)));
      dropped = std::max(dropped, std::abs(fd - Kkk(r, c)));
      scale_h = std::max(scale_h, std::abs(fd));
    }
  }
  MESSAGE(nt << " condensed angles: |torque| " << torque << ", |f - fd| " << worst_f << " of " << scale_f << ", |Schur - fd| "
             << worst_h << " of " << scale_h << " (without the Schur term: " << dropped << ")");
  CHECK(scale_f > 1e-3);
  CHECK(torque < 1e-9 * scale_f);
  CHECK(worst_f < 1e-6 * scale_f);
  CHECK(worst_h < 1e-5 * scale_h);
  CHECK(dropped > 1e3 * worst_h);  // the Schur term is really there on this bent, twisted rod, far above the check's error
}

void perturb_positions(System& sys) {
  std::mt19937 rng(7);
  std::normal_distribution<double> noise(0, 0.01);
  for (double& x : sys.nodes().x()) x += noise(rng);
}

TEST_CASE("condensed twist: forces are the reduced gradient, the Schur complement its Hessian") {
  System sys;
  Rods& rods = hanging_helix(sys, 7);
  rods.condense_twist(sys.angles());
  perturb_positions(sys);
  check_reduced_derivatives(sys);
}

TEST_CASE("condensed twist with held angle DOFs: gradient and Hessian over positions and the held angles") {
  System sys;
  Rods& rods = hanging_helix(sys, 7);
  rods.use_angle_dofs(sys.angles(), 1e-6);
  const std::vector<Rods::RodEdge> held{{0, 3}};
  rods.condense_twist(sys.angles(), held);
  CHECK(rods.has_angle_dofs());
  CHECK_FALSE(sys.angles().condensed(rods.angle_of(0, 3)));
  CHECK(sys.angles().condensed(rods.angle_of(0, 4)));
  CHECK(sys.angles().inertias()[rods.angle_of(0, 4)] == 0.0);
  perturb_positions(sys);
  sys.angles().values()[rods.angle_of(0, 3)] += 0.4;  // the held angle turned: a torque on it
  check_reduced_derivatives(sys);
}

TEST_CASE("condensed twist: Newton follows the quasi-static rods and converges quadratically") {
  System quasi, condensed, quasi_loose, condensed_loose;
  (void)hanging_helix(quasi, 9);
  (void)hanging_helix(quasi_loose, 9);
  hanging_helix(condensed, 9).condense_twist(condensed.angles());
  hanging_helix(condensed_loose, 9).condense_twist(condensed_loose.angles());
  const std::vector<double> angles_before(condensed.angles().values().begin(), condensed.angles().values().end());
  const int it_quasi = run(quasi, 40, 1e-10);
  const int it_condensed = run(condensed, 40, 1e-10);
  const double diff = largest_difference(quasi, condensed);
  // Quadratic convergence: a tolerance 10⁴ times tighter costs at most a couple of iterations a
  // step; the linear convergence of −H_xx pays for every factor it gains.
  const int loose_quasi = run(quasi_loose, 40, 1e-6);
  const int loose_condensed = run(condensed_loose, 40, 1e-6);
  MESSAGE("40 steps, Newton iterations at 1e-6 -> 1e-10 m/s: quasi-static " << loose_quasi << " -> " << it_quasi << ", condensed "
                                                                           << loose_condensed << " -> " << it_condensed
                                                                           << "; positions differ by " << diff << " m");
  CHECK(diff < 1e-9);
  CHECK(it_condensed < it_quasi);
  CHECK(it_condensed <= loose_condensed + 2 * 40);
  // The integrator never turns a condensed angle: the rod's own θ is the state.
  for (std::size_t a = 0; a < angles_before.size(); ++a) CHECK(condensed.angles().values()[a] == angles_before[a]);
}

TEST_CASE("condensed twist with a held angle follows the rods whose angles are all DOFs") {
  System dofs, mixed;
  hanging_helix(dofs, 9).use_angle_dofs(dofs.angles(), 0.0);
  Rods& rods = hanging_helix(mixed, 9);
  rods.use_angle_dofs(mixed.angles(), 0.0);
  const std::vector<Rods::RodEdge> held{{0, 4}};
  rods.condense_twist(mixed.angles(), held);
  const int it_dofs = run(dofs, 40, 1e-10);
  const int it_mixed = run(mixed, 40, 1e-10);
  const Index a = rods.angle_of(0, 4);
  const double angle_diff = std::abs(dofs.angles().values()[a] - mixed.angles().values()[a]);
  MESSAGE("40 steps: Newton iterations all DOFs " << it_dofs << ", condensed but one " << it_mixed << "; positions differ by "
                                                  << largest_difference(dofs, mixed) << " m, the held angle by " << angle_diff << " rad");
  CHECK(largest_difference(dofs, mixed) < 1e-9);
  CHECK(angle_diff < 1e-7);
  CHECK(std::abs(mixed.angles().values()[a] - rods.rod(0).theta()[4]) == 0.0);
}

TEST_CASE("condensed twist: a straight rod that turns freely is solved (its first angle held in the system)") {
  System sys;
  std::vector<Index> ids;
  for (int i = 0; i < 6; ++i) ids.push_back(sys.nodes().add(Vec3(0.05 * i, 0, 0), Vec3::Zero(), 0.001));
  sys.nodes().fix(ids[0]);
  sys.nodes().fix(ids[1]);
  Rods& rods = sys.add<Rods>();
  (void)rods.add_rod(ids, sys.nodes().x(), false, Section::circular(1e7, 0.3, 0.002));
  sys.add<Gravity>(Vec3(0, 0, -9.81));
  REQUIRE(rods.rod(0).turns_freely());
  rods.condense_twist(sys.angles());
  CHECK(sys.angles().fixed(rods.angle_of(0, 0)));
  CHECK_FALSE(sys.angles().fixed(rods.angle_of(0, 1)));
  CHECK_FALSE(rods.has_angle_dofs());
  const int iterations = run(sys, 10, 1e-10);
  MESSAGE("straight free rod, 10 steps: " << iterations << " Newton iterations, tip at z = " << sys.nodes().position(ids[5]).z());
  CHECK(sys.nodes().position(ids[5]).z() < -1e-4);
  CHECK_THROWS_AS(rods.condense_twist(sys.angles()), InputError);
  CHECK_THROWS_AS(rods.use_angle_dofs(sys.angles(), 0.0), InputError);
  System other;
  Rods& more = other.add<Rods>();
  (void)more.add_rod(ids, sys.nodes().x(), false, Section::circular(1e7, 0.3, 0.002));
  const std::vector<Rods::RodEdge> held{{0, 1}};
  CHECK_THROWS_AS(more.condense_twist(other.angles(), held), InputError);  // held before use_angle_dofs
}

}  // namespace angle_dofs_test

}  // namespace test_rod_angle_dofs
