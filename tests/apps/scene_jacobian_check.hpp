#pragma once
// Per-term check of a scene's Jacobians: for every force term, the product (∂F/∂q)·p of its
// exact (unprojected) Jacobian against central differences of that term's own forces along p.
// A term whose Hessian does not match its gradient makes Newton converge linearly on an exact,
// positive definite Hessian; this names the term. Also a stepper of the scene's own bodies
// (motion included), so the check can run at the states a run visits.

#include <algorithm>
#include <cmath>
#include <random>
#include <string>
#include <vector>

#include "../../apps/src/run_build.hpp"
#include "sewn/physics/integrate/newton_euler.hpp"

namespace sewn::app::test {

/// One term's mismatch along one direction: |J p − (F(q+εp) − F(q−εp))/2ε|∞ against |J p|∞.
struct TermJacobianError {
  std::string term;
  double error = 0.0;  ///< largest component of the difference
  double scale = 0.0;  ///< largest component of the difference quotient
  std::size_t worst = 0;  ///< DOF of the largest difference (3 node + axis, then angles)
  [[nodiscard]] double relative() const { return error / std::max(scale, 1e-300); }
};

/// The flat DOFs as NewtonEuler lays them out: 3 per node, then the angles padded to whole
/// blocks of three.
inline std::size_t flat_dofs(const physics::System& sys) {
  return 3 * std::size_t{sys.nodes().size()} + 3 * std::size_t{physics::AngleLayout::blocks_for(sys.angles().size())};
}

/// Checks every term of `sys` at its current state along direction p (flat DOFs; ε the
/// difference step along p). Velocities are taken as zero (∂F/∂q only). The difference is
/// Richardson-extrapolated from steps ε and ε/2, (4 D(ε/2) − D(ε))/3, which cancels the central
/// difference's ε² term: on the toy ball's displaced states a stiff rod's truncation error alone
/// reached 3e-5 of the scale at ε = 1e-4 (falling 100× per decade of ε, down to round-off at
/// 1e-9), so the plain quotient could not tell a wrong Hessian from its own error there.
inline std::vector<TermJacobianError> term_jacobian_errors(physics::System& sys, const std::vector<double>& p, double eps) {
  sys.refresh();
  (void)sys.matrix();  // binds every term's pattern (products need no matrix, but bind it as NewtonEuler does)
  const std::size_t n = flat_dofs(sys), n3 = 3 * std::size_t{sys.nodes().size()}, na = sys.angles().size();
  std::vector<double> q(n, 0.0), zero(n, 0.0);
  const auto x = sys.nodes().x();
  std::copy(x.begin(), x.end(), q.begin());
  for (std::size_t a = 0; a < na; ++a) q[n3 + a] = sys.angles().values()[a];
  const auto view = [&](const std::vector<double>& s) {
    return physics::StateView{std::span<const double>(s).first(n3), std::span<const double>(zero).first(n3), sys.nodes().masses(),
                              std::span<const double>(s).subspan(n3, na), std::span<const double>(zero).subspan(n3, na)};
  };
  std::vector<double> qp(n), qm(n), fp(n), fm(n), jp(n), d_full(n), d_half(n);
  // d = (F(q + h p) − F(q − h p)) / 2h of term t.
  const auto difference = [&](const physics::ForceTerm& t, double h, std::vector<double>& d) {
    for (std::size_t k = 0; k < n; ++k) {
      qp[k] = q[k] + h * p[k];
      qm[k] = q[k] - h * p[k];
    }
    std::fill(fp.begin(), fp.end(), 0.0);
    std::fill(fm.begin(), fm.end(), 0.0);
    t.add_forces(view(qp), fp);
    t.add_forces(view(qm), fm);
    for (std::size_t k = 0; k < n; ++k) d[k] = (fp[k] - fm[k]) / (2 * h);
  };
  std::vector<TermJacobianError> out;
  for (const auto& t : sys.terms()) {
    difference(*t, eps, d_full);
    difference(*t, 0.5 * eps, d_half);
    std::fill(jp.begin(), jp.end(), 0.0);
    physics::JacobianRequest req;
    req.product_in = p;
    req.product_out = jp;
    req.options.project_element_hessians = false;
    req.options.clamp_compression = false;
    req.options.drop_viscous_position_terms = true;
    t->add_jacobians(view(q), req);
    TermJacobianError e{std::string(t->name())};
    for (std::size_t k = 0; k < n; ++k) {
      const double d = (4.0 * d_half[k] - d_full[k]) / 3.0;
      e.scale = std::max(e.scale, std::abs(d));
      if (std::abs(jp[k] - d) > e.error) {
        e.error = std::abs(jp[k] - d);
        e.worst = k;
      }
    }
    out.push_back(e);
  }
  return out;
}

/// A random direction over the free DOFs: positions uniform in ±`length` m, angles in ±`angle` rad.
inline std::vector<double> random_direction(const physics::System& sys, std::mt19937& rng, double length, double angle) {
  const std::size_t n = flat_dofs(sys), n3 = 3 * std::size_t{sys.nodes().size()}, na = sys.angles().size();
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  std::vector<double> p(n, 0.0);
  const auto fixed = sys.nodes().fixed_masks();
  for (std::size_t k = 0; k < n3; ++k)
    if (((fixed[k / 3] >> (k % 3)) & 1) == 0) p[k] = length * u(rng);
  for (std::size_t a = 0; a < na; ++a)
    if (!sys.angles().fixed(static_cast<physics::Index>(a))) p[n3 + a] = angle * u(rng);
  return p;
}

/// The scene's Newton options, as the runner sets them.
inline physics::integrate::NewtonEulerOptions scene_newton_options(const Scene& scene) {
  physics::integrate::NewtonEulerOptions o;
  o.velocity_tolerance = scene.newton_tolerance;
  o.max_iterations = static_cast<int>(scene.newton_iterations);
  o.cg_tolerance = scene.tolerance;
  o.cg_max_iterations = static_cast<int>(scene.max_iterations);
  if (scene.solver == "ldlt" || scene.solver == "cholmod") o.solver = physics::integrate::LinearSolver::ldlt;
  if (scene.solver == "cholmod-pcg") o.solver = physics::integrate::LinearSolver::cholmod_pcg;
  return o;
}

}  // namespace sewn::app::test
