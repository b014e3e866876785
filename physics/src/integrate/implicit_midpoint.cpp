#include "sewn/physics/integrate/implicit_midpoint.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>

#include "sewn/physics/errors.hpp"
#include "sewn/physics/springs.hpp"
#include "../format.hpp"
#include "require_symmetric.hpp"

namespace sewn::physics {

namespace {

double norm2(std::span<const double> a) {
  double s = 0;
  for (double x : a) s += x * x;
  return std::sqrt(s);
}

// Calls f(springs, s, 3·node_i, 3·node_j) for every live spring of every springs term of sys.
template <class F>
void for_each_spring(const System& sys, F&& f) {
  for (const auto& t : sys.terms()) {
    const auto* springs = dynamic_cast<const Springs*>(t.get());
    if (!springs) continue;
    for (Index s = 0; s < springs->size(); ++s)
      if (springs->is_alive(s)) f(*springs, s, 3 * std::size_t{springs->node_i(s)}, 3 * std::size_t{springs->node_j(s)});
  }
}

}  // namespace

ImplicitMidpoint::ImplicitMidpoint(ImplicitMidpointOptions options) : opt_(options) {}

double ImplicitMidpoint::roundoff_estimate(const System& sys, std::span<const double> x, double h) {
  double sum = 0;
  for_each_spring(sys, [&](const Springs& springs, Index s, std::size_t i, std::size_t j) {
    const double xi = std::max({std::abs(x[i]), std::abs(x[i + 1]), std::abs(x[i + 2])});
    const double xj = std::max({std::abs(x[j]), std::abs(x[j + 1]), std::abs(x[j + 2])});
    const double e = springs.stiffness(s) * (xi + xj);
    sum += e * e;
  });
  return h * std::numeric_limits<double>::epsilon() * std::sqrt(sum);
}

CgResult ImplicitMidpoint::solve(const BlockMatrix& A, std::span<const double> b, std::span<double> x) {
  block_jacobi_inverse(A, free_, precond_);
  return filtered_pcg(A, b, x, free_, precond_, opt_.cg_tolerance, opt_.cg_max_iterations, ws_);
}

void ImplicitMidpoint::discrete_gradient(System& sys, double h) const {
  NodeTable& nodes = sys.nodes();
  const auto xm = nodes.x();  // the midpoint state
  const auto f = nodes.f();
  for_each_spring(sys, [&](const Springs& springs, Index s, std::size_t i, std::size_t j) {
    const double k = springs.stiffness(s), l = springs.rest_length(s);
    double dm2 = 0, d02 = 0, d12 = 0, e[3];
    for (std::size_t a = 0; a < 3; ++a) {
      e[a] = xm[j + a] - xm[i + a];
      const double e0 = x0_[j + a] - x0_[i + a];
      const double e1 = e0 + h * (v0_[j + a] - v0_[i + a] + 0.5 * (dv_[j + a] - dv_[i + a]));
      dm2 += e[a] * e[a];
      d02 += e0 * e0;
      d12 += e1 * e1;
    }
    const double dm = std::sqrt(dm2), d0 = std::sqrt(d02), d1 = std::sqrt(d12);
    if (!(dm > 0 && d0 + d1 > 0)) return;  // a spring of zero length has no direction either way
    // (ψ(d₁) − ψ(d₀)) / ((d₁² − d₀²)/2) for ψ = ½k(d − l)², minus the midpoint's own k(1 − l/d̄)
    const double c = k * (1 - 2 * l / (d0 + d1)) - k * (1 - l / dm);
    for (std::size_t a = 0; a < 3; ++a) {
      f[i + a] += c * e[a];
      f[j + a] -= c * e[a];
    }
  });
}

void ImplicitMidpoint::restore(NodeTable& nodes) const {
  std::copy(x0_.begin(), x0_.end(), nodes.x().begin());
  std::copy(v0_.begin(), v0_.end(), nodes.v().begin());
}

StepReport ImplicitMidpoint::step(System& sys, double h) {
  if (!(std::isfinite(h) && h > 0)) throw InputError("ImplicitMidpoint::step: time step must be finite and > 0, got " + detail::format_number(h));
  if (!(opt_.newton_tolerance > 0 && opt_.cg_tolerance > 0 && opt_.max_newton_iterations >= 1 && opt_.cg_max_iterations >= 1 &&
        opt_.max_step_halvings >= 0 && opt_.max_step_halvings <= 20 && opt_.roundoff_factor >= 0 && std::isfinite(opt_.roundoff_factor)))
    throw InputError("ImplicitMidpoint::step: tolerances must be > 0, iteration limits >= 1, max_step_halvings in [0, 20] and "
                     "roundoff_factor finite and >= 0");
  detail::require_symmetric_jacobians(sys, opt_.jacobian, "ImplicitMidpoint::step");
  sys.require_no_angles("ImplicitMidpoint::step");
  StepReport rep;
  rep.pattern_rebuilt = sys.refresh();
  NodeTable& nodes = sys.nodes();
  const std::size_t n3 = 3 * std::size_t{nodes.size()};
  if (dv_.size() != n3) {
    for (auto* a : {&x0_, &v0_, &dv_, &r_, &delta_, &free_, &x_start_, &v_start_}) a->assign(n3, 0.0);
    precond_.assign(9 * std::size_t{nodes.size()}, 0.0);
  }
  if (opt_.health.energy_check_interval > 0) watchdog_.baseline_if_needed(sys);
  std::copy(nodes.x().begin(), nodes.x().end(), x_start_.begin());
  std::copy(nodes.v().begin(), nodes.v().end(), v_start_.begin());
  substeps_ = 0;
  finest_ = 0;
  newton_iterations_ = 0;
  residual_over_roundoff_ = 0;
  if (!advance(sys, h, 0, rep)) {
    std::copy(x_start_.begin(), x_start_.end(), nodes.x().begin());
    std::copy(v_start_.begin(), v_start_.end(), nodes.v().begin());
    throw SolverError("ImplicitMidpoint::step: " + failure_ + ", even with the step split into " +
                          std::to_string(1 << opt_.max_step_halvings) + " sub-steps of " +
                          detail::format_number(h / (1 << opt_.max_step_halvings)) + " s (options max_step_halvings = " +
                          std::to_string(opt_.max_step_halvings) + "); take a smaller step; the state is unchanged",
                      newton_iterations_, failure_residual_);
  }
  return rep;
}

bool ImplicitMidpoint::advance(System& sys, double h, int depth, StepReport& rep) {
  if (attempt(sys, h, rep)) {
    ++substeps_;
    finest_ = std::max(finest_, depth);
    return true;
  }
  // Newton failed (the midpoint state left unchanged): two half steps compose to a step that
  // keeps the same momenta and energy, and each turns the springs half as far
  if (depth == opt_.max_step_halvings) return false;
  return advance(sys, h / 2, depth + 1, rep) && advance(sys, h / 2, depth + 1, rep);
}

bool ImplicitMidpoint::attempt(System& sys, double h, StepReport& rep) {
  NodeTable& nodes = sys.nodes();
  const Index n = nodes.size();
  const std::size_t n3 = 3 * std::size_t{n};
  const bool watch = opt_.health.energy_check_interval > 0;
  {
    const auto x = nodes.x(), v = nodes.v();
    std::copy(x.begin(), x.end(), x0_.begin());
    std::copy(v.begin(), v.end(), v0_.begin());
  }
  const auto mass = nodes.masses();
  const auto fixed = nodes.fixed_masks();
  for (Index i = 0; i < n; ++i)
    for (int a = 0; a < 3; ++a) free_[3 * i + a] = ((fixed[i] >> a) & 1u) ? 0.0 : 1.0;
  double momentum = 0;  // ‖M v₀‖₂, part of the residual's scale
  for (std::size_t k = 0; k < n3; ++k) momentum += (mass[k / 3] * v0_[k]) * (mass[k / 3] * v0_[k]);
  momentum = std::sqrt(momentum);
  std::fill(dv_.begin(), dv_.end(), 0.0);
  // the positions move little within a step: the estimate at its start stands for all of it
  const double roundoff = roundoff_estimate(sys, x0_, h);

  int iterations = 0;
  double residual = 0, scale = 0;
  for (;;) {
    // 1) the midpoint state and the residual r = h F(x̄, v̄) − M Δv (0 on fixed axes)
    {
      const auto x = nodes.x(), v = nodes.v();
      for (std::size_t k = 0; k < n3; ++k) {
        x[k] = x0_[k] + 0.5 * h * v0_[k] + 0.25 * h * dv_[k];
        v[k] = v0_[k] + 0.5 * dv_[k];
      }
    }
    sys.compute_forces();
    if (opt_.discrete_gradient_springs) discrete_gradient(sys, h);
    const auto f = nodes.f();
    double hf = 0, mdv = 0;
    bool finite = true;
    for (std::size_t k = 0; k < n3; ++k) {
      const double m_dv = mass[k / 3] * dv_[k];
      r_[k] = free_[k] * (h * f[k] - m_dv);
      hf += h * h * f[k] * f[k];
      mdv += m_dv * m_dv;
      finite = finite && std::isfinite(r_[k]);
    }
    if (!finite) {
      restore(nodes);
      failure_ = "non-finite forces at the midpoint state after " + std::to_string(iterations) + " Newton iterations";
      failure_residual_ = std::numeric_limits<double>::infinity();
      return false;
    }
    const double previous = residual;
    residual = norm2(r_);
    scale = momentum + std::sqrt(mdv) + std::sqrt(hf);
    if (residual <= opt_.newton_tolerance * scale) break;
    // Round-off floor: the residual sums forces that each carry their own rounding, so below
    // some level a Newton step no longer shrinks it. Accept that level if it is small against
    // the momentum in play or near what round-off allows (a stiff body near rest).
    if (iterations > 0 && residual > 0.5 * previous &&
        residual <= std::max(opt_.stagnation_tolerance * scale, opt_.roundoff_factor * roundoff))
      break;
    if (iterations == opt_.max_newton_iterations) {
      restore(nodes);
      failure_ = "Newton stopped after " + std::to_string(iterations) + " iterations at residual " + detail::format_number(residual) +
                 " (" + detail::format_number(residual / scale) + " of the momentum and impulse in play, tolerance " +
                 detail::format_number(opt_.newton_tolerance) + "; " + detail::format_number(residual / roundoff) +
                 " times the springs' round-off estimate)";
      failure_residual_ = residual / scale;
      return false;
    }
    // 2) the Newton matrix M − (h²/4)∂F/∂x − (h/2)∂F/∂v at the midpoint, and δ
    BlockMatrix& A = sys.matrix();
    A.set_zero();
    JacobianRequest req;
    req.matrix = &A;
    req.cx = -0.25 * h * h;
    req.cv = -0.5 * h;
    req.options = opt_.jacobian;
    sys.add_jacobians(req);
    for (Index i = 0; i < n; ++i) A.block(A.diagonal(i)).diagonal().array() += mass[i];
    std::fill(delta_.begin(), delta_.end(), 0.0);
    const CgResult cg = solve(A, r_, delta_);
    rep.cg_iterations += cg.iterations;
    rep.cg_relative_residual = cg.relative_residual;
    if (!cg.converged) {
      restore(nodes);
      failure_ = "CG stopped after " + std::to_string(cg.iterations) + " iterations at relative residual " +
                 detail::format_number(cg.relative_residual) + " (tolerance " + detail::format_number(opt_.cg_tolerance) +
                 ") in Newton iteration " + std::to_string(iterations + 1) +
                 (cg.breakdown ? "; breakdown: the matrix is not positive definite" : "");
      failure_residual_ = cg.relative_residual;
      return false;
    }
    for (std::size_t k = 0; k < n3; ++k) dv_[k] += delta_[k];
    ++iterations;
    ++newton_iterations_;
  }

  // 3) v₁ = v₀ + Δv, x₁ = x₀ + h (v₀ + v₁)/2; the forces array keeps F(x̄, v̄)
  double max_speed = 0;
  bool finite = true;
  {
    const auto x = nodes.x(), v = nodes.v();
    for (std::size_t k = 0; k < n3; ++k) {
      v[k] = v0_[k] + dv_[k];
      x[k] = x0_[k] + h * (v0_[k] + 0.5 * dv_[k]);
      max_speed = std::max(max_speed, std::abs(v[k]));
      finite = finite && std::isfinite(x[k]) && std::isfinite(v[k]);
    }
  }
  if (finite) nodes.mark_state_finite();
  rep.cg_converged = true;
  if (roundoff > 0) residual_over_roundoff_ = std::max(residual_over_roundoff_, residual / roundoff);
  ++steps_;
  if (watch && finite)
    if (auto blowup = watchdog_.after_step(sys, opt_.health, steps_, max_speed)) {
      const double suggested = h / 10;
      throw BlowupError("ImplicitMidpoint::step: " + blowup->message + " at h = " + detail::format_number(h) + " s; suggested step " +
                            detail::format_number(suggested) + " s",
                        blowup->node, "energy", steps_, suggested);
    }
  return true;
}

}  // namespace sewn::physics
