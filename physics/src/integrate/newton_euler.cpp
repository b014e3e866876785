#include "sewn/physics/integrate/newton_euler.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>

#include <Eigen/SparseCholesky>

#include "sewn/physics/solve/linear_solver.hpp"

namespace sewn::physics::integrate {

struct NewtonEuler::LdltCache {
  Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>> solver;
  std::uint64_t pattern = ~std::uint64_t{0};
  // CHOLMOD's supernodal factorization when the build has it: the same direct solve, several
  // times faster than the simplicial LDLT on a shell of thousands of nodes (the umbrella).
  std::unique_ptr<solve::LinearSolver> cholmod;
  bool cholmod_failed = false;  // the matrix was not positive definite once: LDLT from then on
  // LinearSolver::cholmod_pcg: its factorization is kept across iterations and steps.
  std::unique_ptr<solve::LinearSolver> kept_pcg;
};

NewtonEuler::NewtonEuler(NewtonEulerOptions options) : opt_(options) {}
NewtonEuler::~NewtonEuler() = default;
NewtonEuler::NewtonEuler(NewtonEuler&&) noexcept = default;
NewtonEuler& NewtonEuler::operator=(NewtonEuler&&) noexcept = default;

void NewtonEuler::prepare(System& sys, double h) {
  const NodeTable& nodes = sys.nodes();
  const AngleTable& angles = sys.angles();
  n3_ = 3 * std::size_t{nodes.size()};
  const std::size_t na = angles.size();
  // Angles follow the positions, padded to whole 3×3 blocks (AngleLayout); the padding is fixed.
  const std::size_t total = n3_ + 3 * std::size_t{AngleLayout::blocks_for(angles.size())};
  for (auto* a : {&xn_, &vn_, &qhat_, &q_, &trial_, &inertia_, &free_, &condensed_, &length_, &g_, &f_, &fv_, &f0_, &vel_, &p_, &rhs_})
    a->assign(total, 0.0);
  zeros_.assign(total, 0.0);
  precond_.resize(3 * total);
  ws_.resize(total);
  h_ = h;
  const auto x = nodes.x(), v = nodes.v();
  const auto m = nodes.masses();
  const auto fixed = nodes.fixed_masks();
  for (std::size_t k = 0; k < n3_; ++k) {
    if (!std::isfinite(x[k]) || !std::isfinite(v[k])) {
      std::ostringstream s;
      s << "newton euler: the state is not finite at node " << k / 3 << " (" << (std::isfinite(x[k]) ? "velocity" : "position")
        << ") before the step";
      throw NewtonError(s.str(), NewtonError::non_finite, {});
    }
    xn_[k] = x[k];
    vn_[k] = v[k];
    inertia_[k] = m[k / 3];
    free_[k] = ((fixed[k / 3] >> (k % 3)) & 1) ? 0.0 : 1.0;
    length_[k] = 1.0;
  }
  for (std::size_t a = 0; a < na; ++a) {
    const std::size_t k = n3_ + a;
    xn_[k] = angles.values()[a];
    vn_[k] = angles.rates()[a];
    if (!std::isfinite(xn_[k]) || !std::isfinite(vn_[k]))
      throw NewtonError("newton euler: angle " + std::to_string(a) + " or its rate is not finite before the step",
                        NewtonError::non_finite, {});
    inertia_[k] = angles.inertias()[a];
    free_[k] = angles.fixed(static_cast<Index>(a)) ? 0.0 : 1.0;
    condensed_[k] = angles.condensed(static_cast<Index>(a)) ? 1.0 : 0.0;
    length_[k] = angles.lengths()[a];
  }
  for (std::size_t k = n3_ + na; k < total; ++k) inertia_[k] = 1.0;
  for (std::size_t k = 0; k < total; ++k) qhat_[k] = xn_[k] + h * vn_[k];
  // Velocity-dependent forces enter Φ through the terms' dissipation potentials Ψ, lagged at
  // x_n: f0_ = Σ F(x_n, 0) of the dissipative terms, so that F(x_n, v) - f0_ = -∂Ψ/∂v. A term
  // whose forces depend on velocity without a Ψ cannot be minimised: probe each such term with
  // a non-uniform velocity (a uniform one leaves springs' relative velocities zero) and refuse.
  std::fill(f0_.begin(), f0_.end(), 0.0);
  for (const auto& t : sys.terms()) {
    if (t->dissipative()) {
      t->add_forces(view(sys, xn_, zeros_), f0_);
    } else if (t->velocity_dependent()) {
      probe_velocity_dependence(sys, *t);
    }
  }
}

void NewtonEuler::probe_velocity_dependence(const System& sys, const ForceTerm& t) {
  const std::size_t total = dof_count();
  for (std::size_t k = 0; k < total; ++k) vel_[k] = 1.0 + 0.1 * static_cast<double>(k % 7);
  std::fill(f_.begin(), f_.end(), 0.0);
  std::fill(fv_.begin(), fv_.end(), 0.0);
  t.add_forces(view(sys, xn_, zeros_), f_);
  t.add_forces(view(sys, xn_, vel_), fv_);
  for (std::size_t k = 0; k < total; ++k)
    if (fv_[k] != f_[k])
      throw InputError("newton euler: the term '" + std::string(t.name()) +
                       "' has velocity-dependent forces but no dissipation potential (ForceTerm::dissipative), which "
                       "backward Euler as an incremental potential needs");
}

StateView NewtonEuler::view(const System& sys, std::span<const double> q, std::span<const double> vel) const {
  const std::size_t na = sys.angles().size();
  return {q.first(n3_), vel.first(n3_), sys.nodes().masses(), q.subspan(n3_, na), vel.subspan(n3_, na)};
}

std::string NewtonEuler::describe_dof(std::size_t k) const {
  return k < n3_ ? "node " + std::to_string(k / 3) : "angle " + std::to_string(k - n3_);
}

double NewtonEuler::evaluate(const System& sys, std::span<const double> q, bool want_gradient) {
  const std::size_t n = dof_count();
  for (std::size_t k = 0; k < n; ++k) vel_[k] = free_[k] != 0.0 ? (q[k] - xn_[k]) / h_ : vn_[k];
  const StateView s = view(sys, q, vel_);
  double phi = 0.0;
  for (std::size_t k = 0; k < n; ++k) {
    const double d = q[k] - qhat_[k];
    phi += free_[k] * inertia_[k] * d * d;
  }
  phi *= 0.5 / (h_ * h_);
  // f_ = F(q, v) of the terms without dissipation; a dissipative term contributes its
  // elastic part F(q, 0) and its damping at the lagged positions, F(x_n, v) - F(x_n, 0) (the
  // last sum in f0_, from prepare()), and h Ψ(x_n, v) to Φ, whose q-gradient that damping is.
  // Energy and forces of a term come from one pass where it can (add_forces_and_energy).
  if (want_gradient) std::fill(f_.begin(), f_.end(), 0.0);
  for (const auto& t : sys.terms()) {
    if (!want_gradient) {
      phi += t->potential_energy(s);
    } else if (!t->dissipative()) {
      phi += t->add_forces_and_energy(s, f_);
    } else {
      phi += t->potential_energy(s);
      t->add_forces(view(sys, q, zeros_), f_);
    }
  }
  const StateView lagged = view(sys, xn_, vel_);
  for (const auto& t : sys.terms()) {
    if (!t->dissipative()) continue;
    phi += h_ * t->dissipation(lagged);
    if (want_gradient) t->add_forces(lagged, f_);
  }
  if (want_gradient)
    for (std::size_t k = 0; k < n; ++k)
      g_[k] = free_[k] * (inertia_[k] * (q[k] - qhat_[k]) / (h_ * h_) - (f_[k] - f0_[k]));
  return phi;
}

void NewtonEuler::assemble(System& sys, bool project) {
  BlockMatrix& A = sys.matrix();
  A.set_zero();
  JacobianRequest req;
  req.matrix = &A;
  req.cx = -1.0;
  req.cv = -1.0 / h_;
  req.options.project_element_hessians = project;
  req.options.clamp_compression = project;
  req.options.drop_viscous_position_terms = true;
  const StateView s = view(sys, q_, vel_);
  for (const auto& t : sys.terms()) t->add_jacobians(s, req);
  for (Index i = 0; i < A.size(); ++i)
    for (int c = 0; c < 3; ++c) A.block(A.diagonal(i))(c, c) += inertia_[3 * std::size_t{i} + static_cast<std::size_t>(c)] / (h_ * h_);
}

int NewtonEuler::solve_linear(const BlockMatrix& A, bool need_definite) {
  const std::size_t n = dof_count();
  for (std::size_t k = 0; k < n; ++k) {
    rhs_[k] = -g_[k];
    p_[k] = 0.0;
  }
  if (opt_.solver == LinearSolver::cg) {
    block_jacobi_inverse(A, free_, precond_);
    const CgResult r = filtered_pcg(A, rhs_, p_, free_, precond_, opt_.cg_tolerance, opt_.cg_max_iterations, ws_);
    return r.iterations;
  }
  if (!ldlt_) ldlt_ = std::make_unique<LdltCache>();
  if (opt_.solver == LinearSolver::cholmod_pcg) return solve_kept_pcg(A, eta_);
  if (solve::available(solve::Backend::cholmod) && !ldlt_->cholmod_failed) {
    if (!ldlt_->cholmod) {
      solve::SolverOptions o;
      o.tolerance = 1e-12;  // a direct solve: refinement passes only where round-off shows
      o.absolute_tolerance = 0.0;
      ldlt_->cholmod = solve::make_solver(solve::Backend::cholmod, o);
    }
    try {
      (void)ldlt_->cholmod->solve(A, std::span<const double>(rhs_.data(), n), std::span<double>(p_.data(), n),
                                  std::span<const double>(free_.data(), n));
      return 0;
    } catch (const SolverError&) {
      std::fill(p_.begin(), p_.begin() + static_cast<std::ptrdiff_t>(n), 0.0);
      if (need_definite) return -1;
      // The projected H plus the inertia is positive definite but for round-off; where
      // CHOLMOD's pivot still fails, LDLT below handles the semi-definite matrix.
      ldlt_->cholmod_failed = true;
    }
  }
  // LDLT on the sparse copy with fixed rows and columns replaced by the identity; the
  // pattern (hence the symbolic factorisation) does not depend on which axes are fixed.
  Eigen::SparseMatrix<double> S = A.to_sparse();
  for (int c = 0; c < S.outerSize(); ++c)
    for (Eigen::SparseMatrix<double>::InnerIterator it(S, c); it; ++it)
      if (free_[it.row()] == 0.0 || free_[it.col()] == 0.0) it.valueRef() = it.row() == it.col() ? 1.0 : 0.0;
  if (ldlt_->pattern != A.pattern_version()) {
    ldlt_->solver.analyzePattern(S);
    ldlt_->pattern = A.pattern_version();
  }
  ldlt_->solver.factorize(S);
  if (ldlt_->solver.info() != Eigen::Success) return need_definite ? -1 : 0;  // p stays 0: reported as no descent
  if (need_definite && !(ldlt_->solver.vectorD().minCoeff() > 0.0)) return -1;
  Eigen::Map<Eigen::VectorXd> p(p_.data(), static_cast<Eigen::Index>(n));
  p = ldlt_->solver.solve(Eigen::Map<const Eigen::VectorXd>(rhs_.data(), static_cast<Eigen::Index>(n)));
  for (std::size_t k = 0; k < n; ++k) p_[k] *= free_[k];
  return 0;
}

void NewtonEuler::limit_angle_step(double& slope, double& pmax, NewtonReport& rep) {
  const std::size_t n = dof_count();
  double largest = 0.0;  // a condensed angle is its term's to turn (its own solve limits it)
  for (std::size_t k = n3_; k < n; ++k) largest = std::max(largest, (1.0 - condensed_[k]) * std::abs(p_[k]));
  if (!(largest > opt_.max_angle_step)) return;
  // Scaling the whole step keeps it a descent direction (gᵀp scales with it) and its shape.
  const double s = opt_.max_angle_step / largest;
  for (std::size_t k = 0; k < n; ++k) p_[k] *= s;
  slope *= s;
  pmax *= s;
  ++rep.angle_step_limits;
}

double NewtonEuler::term_step_fraction(const System& sys, std::span<const double> q, std::span<const double> dq) const {
  const StateView from = view(sys, q, zeros_), change = view(sys, dq, zeros_);
  double alpha = 1.0;
  for (const auto& t : sys.terms()) alpha = std::min(alpha, t->step_fraction(from, change));
  return alpha;
}

void NewtonEuler::predict(const System& sys, NewtonReport& rep) {
  const std::size_t n = dof_count();
  // The fraction along the whole state's path q_n → q̂, prescribed axes included, so that a
  // rigid prescribed motion (which turns no joint) is taken whole; the fixed axes are at q̂
  // whatever the fraction.
  for (std::size_t k = 0; k < n; ++k) p_[k] = qhat_[k] - xn_[k];
  rep.guess_fraction = term_step_fraction(sys, xn_, p_);
  if (rep.guess_fraction == 1.0) {
    std::copy(qhat_.begin(), qhat_.end(), q_.begin());  // q̂ to the bit
    return;
  }
  for (std::size_t k = 0; k < n; ++k) q_[k] = free_[k] != 0.0 ? xn_[k] + rep.guess_fraction * p_[k] : qhat_[k];
}

void NewtonEuler::limit_term_step(const System& sys, double& slope, NewtonReport& rep) {
  const double s = term_step_fraction(sys, q_, p_);
  if (!(s < 1.0)) return;
  for (std::size_t k = 0; k < dof_count(); ++k) p_[k] *= s;
  slope *= s;
  ++rep.term_step_limits;
}

solve::LinearSolver& NewtonEuler::kept_pcg() {
  if (!ldlt_) ldlt_ = std::make_unique<LdltCache>();
  if (!ldlt_->kept_pcg) {
    if (!solve::available(solve::Backend::cholmod_pcg))
      throw InputError("newton euler: the solver cholmod-pcg needs CHOLMOD, which this build lacks");
    solve::SolverOptions o;
    o.tolerance = opt_.cg_tolerance;
    o.absolute_tolerance = 0.0;  // relative to the Newton residual, as the block-Jacobi CG
    o.max_iterations = opt_.cg_max_iterations;
    ldlt_->kept_pcg = solve::make_solver(solve::Backend::cholmod_pcg, o);
  }
  return *ldlt_->kept_pcg;
}

int NewtonEuler::solve_kept_pcg(const BlockMatrix& A, double tolerance) {
  const std::size_t n = dof_count();
  solve::LinearSolver& solver = kept_pcg();
  solver.options().tolerance = tolerance;
  try {
    const solve::SolveReport r = solver.solve(A, std::span<const double>(rhs_.data(), n), std::span<double>(p_.data(), n),
                                              std::span<const double>(free_.data(), n));
    return r.iterations;
  } catch (const SolverError&) {
    // A fresh factorization of the projected H failed (round-off on a semi-definite matrix):
    // p = 0 is no descent, and step() falls back on the scaled gradient.
    std::fill(p_.begin(), p_.begin() + static_cast<std::ptrdiff_t>(n), 0.0);
    solver.reset();
    return 0;
  }
}

NewtonEuler::History NewtonEuler::history(const System& sys) const {
  History h;
  if (!ldlt_) return h;
  h.direct_failed = ldlt_->cholmod_failed;
  if (ldlt_->kept_pcg && sys.topology_key() == kept_topology_) h.solver = ldlt_->kept_pcg->state();
  return h;
}

void NewtonEuler::restore(System& sys, const History& h) {
  // A fresh cache, as at the start of a run, then what the history says it held.
  ldlt_ = std::make_unique<LdltCache>();
  ldlt_->cholmod_failed = h.direct_failed;
  const bool kept = !h.solver.factored.empty() || h.solver.refresh_due || h.solver.cycle_solves != 0;
  if (!kept) return;
  sys.refresh();
  kept_pcg().restore(sys.matrix(), h.solver);
  kept_topology_ = sys.topology_key();
}

void NewtonEuler::steepest_descent(const BlockMatrix& A, double& slope, double& pmax) {
  slope = pmax = 0.0;
  for (std::size_t k = 0; k < dof_count(); ++k) {
    const double d = A.block(A.diagonal(static_cast<Index>(k / 3)))(k % 3, k % 3);
    p_[k] = free_[k] * (-g_[k] / d);
    slope += g_[k] * p_[k];
    pmax = std::max(pmax, std::abs(p_[k]));
  }
}

void NewtonEuler::drop_condensed(double& slope) {
  for (std::size_t k = n3_; k < dof_count(); ++k)
    if (condensed_[k] != 0.0) {
      slope -= g_[k] * p_[k];
      p_[k] = 0.0;
    }
}

double NewtonEuler::largest_move() const {
  double moved = 0.0;
  for (std::size_t k = 0; k < dof_count(); ++k) moved = std::max(moved, length_[k] * std::abs(p_[k]));
  return moved;
}

double NewtonEuler::gradient_norm() const {
  double gg = 0.0;
  for (std::size_t k = 0; k < dof_count(); ++k) gg += g_[k] * g_[k];  // g_ is zero on fixed axes
  return std::sqrt(gg);
}

double NewtonEuler::forcing_term(double g_now, double g_prev, bool first) const {
  const double loosest = opt_.cg_forcing_max;
  if (!(loosest > opt_.cg_tolerance) || opt_.solver != LinearSolver::cholmod_pcg) return opt_.cg_tolerance;
  // Eisenstat & Walker's second choice, η = γ (‖g_k‖ / ‖g_{k-1}‖)², γ = 0.9: loose while
  // Newton is far from the solution (the linear model is poor there), tightening as the
  // gradient falls fast; with their safeguard against dropping faster than the last η allows.
  if (first || !(g_prev > 0.0)) return loosest;
  constexpr double gamma = 0.9;
  const double ratio = g_now / g_prev;
  double eta = gamma * ratio * ratio;
  const double guard = gamma * eta_ * eta_;
  if (guard > 0.1) eta = std::max(eta, guard);
  return std::clamp(eta, opt_.cg_tolerance, loosest);
}

double NewtonEuler::incremental_potential(const System& sys, std::span<const double> q) {
  return evaluate(sys, q, false);
}

NewtonReport NewtonEuler::step(System& sys, double h) {
  if (!std::isfinite(h) || h <= 0.0) throw InputError("newton euler: step h must be finite and > 0, got " + std::to_string(h));
  if (!(opt_.max_angle_step > 0.0))
    throw InputError("newton euler: max_angle_step must be > 0 rad (infinity: no limit), got " + std::to_string(opt_.max_angle_step));
  sys.refresh();
  prepare(sys, h);
  NewtonReport rep;
  const std::size_t n = dof_count();
  predict(sys, rep);
  double phi = evaluate(sys, q_, true);
  const double phi0 = phi;
  auto fail = [&](NewtonError::Reason why, const std::string& what) {
    throw NewtonError("newton euler: " + what + " (after " + std::to_string(rep.iterations) + " iterations, |p|inf/h = " +
                          std::to_string(rep.step_velocity) + " m/s); the state is unchanged",
                      why, rep);
  };
  auto first_non_finite = [&](const AlignedVector<double>& a) {
    for (std::size_t k = 0; k < n; ++k)
      if (!std::isfinite(a[k])) return static_cast<long long>(k);
    return -1LL;
  };
  if (!std::isfinite(phi)) fail(NewtonError::non_finite, "the incremental potential is not finite at the initial guess");
  if (const auto k = first_non_finite(g_); k >= 0)
    fail(NewtonError::non_finite, "the gradient is not finite at " + describe_dof(static_cast<std::size_t>(k)));

  bool converged = false;
  double g_prev = 0.0;  // ‖g‖₂ at the previous iteration (forcing terms)
  eta_ = opt_.cg_tolerance;
  while (!converged) {
    if (rep.iterations >= opt_.max_iterations) fail(NewtonError::too_many_iterations, "no convergence in the iteration limit");
    ++rep.iterations;
    double slope = 0.0, pmax = 0.0;
    const auto measure = [&] {
      slope = pmax = 0.0;
      for (std::size_t k = 0; k < n; ++k) {
        slope += g_[k] * p_[k];
        pmax = std::max(pmax, std::abs(p_[k]));
      }
      return slope < 0.0 && std::isfinite(pmax);
    };
    bool exact = opt_.exact_hessian_first && opt_.solver == LinearSolver::ldlt;
    if (exact) {
      assemble(sys, false);
      exact = solve_linear(sys.matrix(), true) >= 0 && measure();
      if (!exact) ++rep.projected_retries;
    }
    if (!exact) {
      assemble(sys, true);
      const double g_now = gradient_norm();
      eta_ = forcing_term(g_now, g_prev, rep.iterations == 1);
      g_prev = g_now;
      rep.linear_iterations += solve_linear(sys.matrix());
      (void)measure();
    }
    if (!(slope < 0.0) || !std::isfinite(pmax)) {
      // An inexact or failed solve: fall back on the Jacobi-scaled gradient, always a descent.
      ++rep.steepest_fallbacks;
      steepest_descent(sys.matrix(), slope, pmax);
    }
    limit_angle_step(slope, pmax, rep);
    // The stopping test counts an angle's update as the distance it moves its material
    // (length × Δθ), so it compares metres with metres.
    double moved = largest_move();
    if (moved / h < opt_.velocity_tolerance && eta_ > opt_.cg_tolerance && opt_.solver == LinearSolver::cholmod_pcg) {
      // A loose solve (forcing term) passed the stopping test: the test is meant for a step
      // solved to cg_tolerance, so finish the solve from where it stopped and test again.
      rep.linear_iterations += solve_kept_pcg(sys.matrix(), opt_.cg_tolerance);
      eta_ = opt_.cg_tolerance;
      ++rep.forcing_refinements;
      if (!measure()) {
        ++rep.steepest_fallbacks;
        steepest_descent(sys.matrix(), slope, pmax);
      }
      limit_angle_step(slope, pmax, rep);
      moved = largest_move();
    }
    rep.step_velocity = moved / h;
    drop_condensed(slope);
    if (pmax == 0.0 || rep.step_velocity < opt_.velocity_tolerance) {
      // The Newton step is within tolerance: take it whole (it is smaller than what the
      // line search could resolve against round-off in Φ).
      for (std::size_t k = 0; k < n; ++k) q_[k] += p_[k];
      phi = evaluate(sys, q_, false);  // for phi_decrease; no gradient is needed after
      converged = true;
      break;
    }
    limit_term_step(sys, slope, rep);
    // Armijo backtracking; round-off in Φ is allowed for at a few ulps of its terms' size. The
    // first trial evaluates the gradient too (g_ at q_ is not needed again: slope holds what the
    // test uses): α = 1 is accepted nearly always, and its gradient is then already there.
    double alpha = 1.0;
    const double noise = 8.0 * std::numeric_limits<double>::epsilon() * std::abs(phi);
    for (int ls = 0;; ++ls) {
      if (ls > opt_.max_line_search) fail(NewtonError::no_descent, "the line search found no decrease of the incremental potential");
      for (std::size_t k = 0; k < n; ++k) trial_[k] = q_[k] + alpha * p_[k];
      const double phi_t = evaluate(sys, trial_, ls == 0);
      if (std::isfinite(phi_t) && phi_t <= phi + opt_.armijo * alpha * slope + noise) {
        std::swap(q_, trial_);
        rep.last_alpha = alpha;
        phi = ls == 0 ? phi_t : evaluate(sys, q_, true);
        break;
      }
      alpha *= 0.5;
      ++rep.line_search_steps;
    }
    if (!std::isfinite(phi)) fail(NewtonError::non_finite, "the incremental potential became non-finite");
    if (const auto k = first_non_finite(g_); k >= 0)
      fail(NewtonError::non_finite, "the gradient is not finite at " + describe_dof(static_cast<std::size_t>(k)));
  }
  if (const auto k = first_non_finite(q_); k >= 0)
    fail(NewtonError::non_finite, "the new state is not finite at " + describe_dof(static_cast<std::size_t>(k)));
  rep.phi_decrease = phi0 - phi;
  NodeTable& nodes = sys.nodes();
  auto x = nodes.x();
  auto v = nodes.v();
  for (std::size_t k = 0; k < n3_; ++k) {
    x[k] = q_[k];
    if (free_[k] != 0.0) v[k] = (q_[k] - xn_[k]) / h;
  }
  AngleTable& angles = sys.angles();
  for (std::size_t a = 0; a < angles.size(); ++a) {
    const std::size_t k = n3_ + a;
    angles.values()[a] = q_[k];
    if (free_[k] != 0.0) angles.rates()[a] = (q_[k] - xn_[k]) / h;
  }
  nodes.mark_state_finite();
  if (opt_.solver == LinearSolver::cholmod_pcg) kept_topology_ = sys.topology_key();
  // History frozen within the step (rods' time-parallel frames, connections' accepted twist)
  // moves on to the accepted state.
  sys.step_accepted();
  return rep;
}

}  // namespace sewn::physics::integrate
