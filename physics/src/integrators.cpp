#include "sewn/physics/integrators.hpp"

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdint>
#include <sstream>
#include <string>

#include "sewn/physics/errors.hpp"

namespace sewn::physics {

namespace {

std::string fmt(double v) {
  std::ostringstream os;
  os.precision(6);
  os << v;
  return os.str();
}

void check_step(double h, const char* who) {
  if (!(std::isfinite(h) && h > 0)) throw InputError(std::string(who) + ": time step must be finite and > 0, got " + fmt(h));
}

// 1 if x is an infinity or a NaN: an integer test of the exponent bits, which vectorises (as an
// OR reduction) without -ffast-math, which would break NaN tests.
inline std::uint64_t inf_or_nan(double x) {
  constexpr std::uint64_t exponent = 0x7ff0000000000000ull;
  return static_cast<std::uint64_t>((std::bit_cast<std::uint64_t>(x) & exponent) == exponent);
}

// True if every value of the equally long arrays is finite, in one pass.
template <class... Spans>
bool all_finite(std::span<const double> a, Spans... more) {
  std::uint64_t bad = 0;
  for (std::size_t k = 0; k < a.size(); ++k) bad |= (inf_or_nan(a[k]) | ... | inf_or_nan(more[k]));
  return bad == 0;
}

[[noreturn]] void report_nonfinite(const NodeTable& nodes, const char* who, bool with_forces) {
  struct Quantity {
    std::span<const double> values;
    const char* name;
  };
  const Quantity qs[] = {{nodes.x(), "position"}, {nodes.v(), "velocity"}, {nodes.f(), "force"}};
  for (const Quantity& q : qs) {
    if (!with_forces && std::string(q.name) == "force") break;
    for (Index i = 0; i < nodes.size(); ++i) {
      const double* p = q.values.data() + 3 * std::size_t{i};
      if (std::isfinite(p[0]) && std::isfinite(p[1]) && std::isfinite(p[2])) continue;
      std::string msg = std::string(who) + ": " + q.name + " of node " + std::to_string(i) + " is not finite (" +
                        fmt(p[0]) + ", " + fmt(p[1]) + ", " + fmt(p[2]) + "); the step was not taken";
      if (std::string(q.name) == "force") msg += " (positions and velocities are finite: a force term overflowed)";
      throw BlowupError(msg, i, q.name);
    }
  }
  throw BlowupError(std::string(who) + ": non-finite value in the state", invalid_index, "state");
}

void check_finite(const NodeTable& nodes, const char* who) {
  // Positions and velocities that the last update found finite, untouched since, need no
  // second pass; the forces are new.
  const bool ok = nodes.state_known_finite() ? all_finite(nodes.f()) : all_finite(nodes.x(), nodes.v(), nodes.f());
  if (!ok) report_nonfinite(nodes, who, true);
}

}  // namespace

// ------------------------------------------------------------------ EnergyWatchdog

void EnergyWatchdog::baseline_if_needed(const System& sys) {
  const std::uint64_t v = sys.version();
  if (has_baseline_ && v == version_) return;
  internal0_ = sys.kinetic_energy() + sys.potential_energy(EnergyKind::internal);
  external0_ = sys.potential_energy(EnergyKind::external);
  version_ = v;
  has_baseline_ = true;
}

void EnergyWatchdog::check(const System& sys, const HealthOptions& opt, std::uint64_t step) const {
  if (!has_baseline_) return;
  const double internal = sys.kinetic_energy() + sys.potential_energy(EnergyKind::internal);
  const double work = external0_ - sys.potential_energy(EnergyKind::external);
  const double budget = internal0_ + std::max(0.0, work);
  const double floor = opt.energy_floor_fraction * sys.energy_scale();
  if (internal <= opt.energy_growth_factor * budget + floor) return;
  const NodeTable& nodes = sys.nodes();
  Index fastest = invalid_index;
  double vmax = -1;
  for (Index i = 0; i < nodes.size(); ++i) {
    const auto v = nodes.v().subspan(3 * std::size_t{i}, 3);
    const double s = std::sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
    if (s > vmax || (std::isnan(s) && fastest == invalid_index)) {
      vmax = s;
      fastest = i;
    }
  }
  throw BlowupError("energy blow-up after step " + std::to_string(step) + ": kinetic + internal energy " + fmt(internal) +
                        " exceeds " + fmt(opt.energy_growth_factor) + " x its budget " + fmt(budget) +
                        " (baseline energy plus work of external fields) + floor " + fmt(floor) + "; fastest node " +
                        std::to_string(fastest) + " has speed " + fmt(vmax) +
                        ". The time step is probably too large for the scheme.",
                    fastest, "energy");
}

// ------------------------------------------------------------------ SymplecticEuler

SymplecticEuler::SymplecticEuler(SymplecticEulerOptions options) : opt_(options) {}

void SymplecticEuler::reset() {
  bound_ = StableStep{std::numeric_limits<double>::quiet_NaN()};
  watchdog_.reset();
}

StepReport SymplecticEuler::step(System& sys, double h) {
  check_step(h, "SymplecticEuler::step");
  StepReport rep;
  rep.pattern_rebuilt = sys.refresh();
  if (opt_.enforce_stable_step) {
    const std::uint64_t v = sys.version();
    const auto interval = static_cast<std::uint64_t>(std::max(1, opt_.stable_step_recheck_interval));
    if (std::isnan(bound_.h_max) || v != bound_version_ || steps_ - bound_step_ >= interval) {
      bound_ = sys.stable_step();
      bound_version_ = v;
      bound_step_ = steps_;
    }
    rep.stable_step = bound_.h_max;
    if (!(h < bound_.h_max)) {
      throw StabilityError("SymplecticEuler::step: h = " + fmt(h) + " s is not below the stable-step bound " +
                               fmt(bound_.h_max) + " s (omega_max <= " + fmt(std::sqrt(bound_.stiffness_bound)) +
                               " rad/s from node " + std::to_string(bound_.stiffness_node) + ", damping rate <= " +
                               fmt(bound_.damping_bound) + " 1/s). Use a smaller step or LinearlyImplicitEuler, or "
                               "set enforce_stable_step = false; the state is unchanged.",
                           h, bound_.h_max);
    }
  }
  const bool watch = opt_.health.energy_check_interval > 0;
  if (watch) watchdog_.baseline_if_needed(sys);
  sys.compute_forces();
  NodeTable& nodes = sys.nodes();
  if (opt_.health.check_finite) check_finite(nodes, "SymplecticEuler::step");
  SlaveNodes& slaves = sys.slaves();  // T-junctions: forces to their masters, masses lumped there
  if (!slaves.empty()) slaves.pass_forces(nodes.f());
  {
    const std::size_t n3 = nodes.x().size();
    double* __restrict x = nodes.x().data();
    double* __restrict v = nodes.v().data();
    const double* __restrict f = nodes.f().data();
    const double* __restrict im = (slaves.empty() ? nodes.inverse_mass_dof() : slaves.inverse_mass_dof(nodes)).data();
    std::uint64_t bad = 0;
    for (std::size_t k = 0; k < n3; ++k) {
      v[k] += h * im[k] * f[k];
      x[k] += h * v[k];
      bad |= inf_or_nan(v[k]) | inf_or_nan(x[k]);
    }
    if (bad == 0) nodes.mark_state_finite();
  }
  if (!slaves.empty()) slaves.after_step(nodes);
  ++steps_;
  if (watch && steps_ % static_cast<std::uint64_t>(opt_.health.energy_check_interval) == 0)
    watchdog_.check(sys, opt_.health, steps_);
  return rep;
}

// ------------------------------------------------------------------ LinearlyImplicitEuler

LinearlyImplicitEuler::LinearlyImplicitEuler(ImplicitEulerOptions options) : opt_(options) {}

void LinearlyImplicitEuler::reset() {
  std::fill(dv_.begin(), dv_.end(), 0.0);
  watchdog_.reset();
}

StepReport LinearlyImplicitEuler::step(System& sys, double h) {
  check_step(h, "LinearlyImplicitEuler::step");
  if (!(opt_.cg_tolerance > 0 && std::isfinite(opt_.cg_tolerance)))
    throw InputError("LinearlyImplicitEuler::step: cg_tolerance must be finite and > 0, got " + fmt(opt_.cg_tolerance));
  if (opt_.cg_max_iterations < 1)
    throw InputError("LinearlyImplicitEuler::step: cg_max_iterations must be >= 1, got " +
                     std::to_string(opt_.cg_max_iterations));
  for (const auto& t : sys.terms())
    if (!t->jacobian_symmetric(opt_.jacobian))
      throw InputError("LinearlyImplicitEuler::step: term '" + std::string(t->name()) +
                       "' gives a non-symmetric matrix with these JacobianOptions (set "
                       "drop_viscous_position_terms = true); CG needs a symmetric matrix");
  StepReport rep;
  rep.pattern_rebuilt = sys.refresh();
  NodeTable& nodes = sys.nodes();
  const Index n = nodes.size();
  const std::size_t n3 = 3 * std::size_t{n};
  if (dv_.size() != n3) {
    b_.assign(n3, 0.0);
    dv_.assign(n3, 0.0);
    kv_.assign(n3, 0.0);
    free_.assign(n3, 0.0);
    precond_.assign(9 * std::size_t{n}, 0.0);
  }
  const bool watch = opt_.health.energy_check_interval > 0;
  if (watch) watchdog_.baseline_if_needed(sys);

  // 1) forces at the start of the step, checked before anything is changed
  sys.compute_forces();
  if (opt_.health.check_finite) check_finite(nodes, "LinearlyImplicitEuler::step");
  SlaveNodes& slaves = sys.slaves();  // T-junctions: the paper's shares here, or the reduced solve below
  if (!slaves.empty() && !slaves.reduces()) slaves.pass_forces(nodes.f());

  // 2) A = M - h ∂F/∂V - h² ∂F/∂P into the reused pattern, and ∂F/∂P·V₀ in the same pass
  BlockMatrix& A = sys.matrix();
  A.set_zero();
  std::fill(kv_.begin(), kv_.end(), 0.0);
  JacobianRequest req;
  req.matrix = &A;
  req.cx = -h * h;
  req.cv = -h;
  req.product_in = nodes.v();
  req.product_out = kv_;
  req.options = opt_.jacobian;
  sys.add_jacobians(req);
  const auto mass = nodes.masses();
  const auto fixed = nodes.fixed_masks();
  for (Index i = 0; i < n; ++i) {
    A.block(A.diagonal(i)).diagonal().array() += mass[i];
    for (int a = 0; a < 3; ++a) free_[3 * i + a] = ((fixed[i] >> a) & 1u) ? 0.0 : 1.0;
  }

  // 3) b = h (F₀ + h ∂F/∂P V₀); ΔV = 0 on fixed axes (their velocity is prescribed)
  const auto f = nodes.f();
  for (std::size_t k = 0; k < n3; ++k) {
    b_[k] = h * (f[k] + h * kv_[k]);
    if (!opt_.warm_start || free_[k] == 0.0) dv_[k] = 0.0;
  }
  block_jacobi_inverse(A, free_, precond_);
  const CgResult cg = slaves.reduces()
                         ? slaves.solve_reduced(A, b_, dv_, free_, precond_, opt_.cg_tolerance, opt_.cg_max_iterations)
                         : filtered_pcg(A, b_, dv_, free_, precond_, opt_.cg_tolerance, opt_.cg_max_iterations, ws_);
  rep.cg_iterations = cg.iterations;
  rep.cg_relative_residual = cg.relative_residual;
  rep.cg_converged = cg.converged;
  if (!cg.converged && opt_.throw_on_cg_failure) {
    std::fill(dv_.begin(), dv_.end(), 0.0);
    throw SolverError("LinearlyImplicitEuler::step: CG stopped after " + std::to_string(cg.iterations) +
                          " iterations at relative residual " + fmt(cg.relative_residual) + " (tolerance " +
                          fmt(opt_.cg_tolerance) + ")" +
                          (cg.breakdown ? "; breakdown: the matrix is not positive definite (compression with "
                                          "clamp_compression = false?)"
                                        : "") +
                          "; the state is unchanged",
                      cg.iterations, cg.relative_residual);
  }

  // 4) V₁ = V₀ + ΔV, P₁ = P₀ + h V₁
  {
    double* __restrict x = nodes.x().data();
    double* __restrict v = nodes.v().data();
    const double* __restrict dv = dv_.data();
    std::uint64_t bad = 0;
    for (std::size_t k = 0; k < n3; ++k) {
      v[k] += dv[k];
      x[k] += h * v[k];
      bad |= inf_or_nan(v[k]) | inf_or_nan(x[k]);
    }
    if (bad == 0) nodes.mark_state_finite();
  }
  if (!slaves.empty()) slaves.after_step(nodes);
  ++steps_;
  if (watch && steps_ % static_cast<std::uint64_t>(opt_.health.energy_check_interval) == 0)
    watchdog_.check(sys, opt_.health, steps_);
  return rep;
}

}  // namespace sewn::physics
