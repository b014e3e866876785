#include "sewn/physics/integrators.hpp"

#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <cstdint>
#include <string>

#include "sewn/physics/errors.hpp"
#include "format.hpp"
#include "integrate/require_symmetric.hpp"
#include "parallel/ranges.hpp"

namespace sewn::physics {

namespace {

void check_step(double h, const char* who) {
  if (!(std::isfinite(h) && h > 0)) throw InputError(std::string(who) + ": time step must be finite and > 0, got " + detail::format_number(h));
}

// 1 if x is an infinity or a NaN: an integer test of the exponent bits, which vectorises (as an
// OR reduction) without -ffast-math, which would break NaN tests.
inline std::uint64_t inf_or_nan(double x) {
  constexpr std::uint64_t exponent = 0x7ff0000000000000ull;
  return static_cast<std::uint64_t>((std::bit_cast<std::uint64_t>(x) & exponent) == exponent);
}

// |x| as its bit pattern: ordered like |x| for non-negative doubles, NaN above infinity, and
// an integer max-reduction vectorises where a floating-point one would need -ffast-math.
inline std::uint64_t abs_bits(double x) { return std::bit_cast<std::uint64_t>(x) & std::uint64_t{0x7fffffffffffffff}; }

// Values per thread below which the integrators' vector passes stay on one thread (the CG's
// 1024 nodes: these passes read and write as much per value as CG's vector updates).
constexpr std::size_t vector_grain = 3 * 1024;

// True if every value of the equally long arrays is finite, in one pass; split in ranges at
// 2+ threads (an OR of flags: the same answer for any grouping).
template <class... Spans>
bool all_finite(std::span<const double> a, Spans... more) {
  const int parts = detail::parts_for(a.size(), vector_grain);
  std::array<std::uint64_t, max_threads> bad_of{};
  detail::run_parts(parts, [&](int t) {
    std::uint64_t bad = 0;
    const std::size_t k1 = detail::range_begin(a.size(), parts, t + 1);
    for (std::size_t k = detail::range_begin(a.size(), parts, t); k < k1; ++k)
      bad |= (inf_or_nan(a[k]) | ... | inf_or_nan(more[k]));
    bad_of[static_cast<std::size_t>(t)] = bad;
  });
  std::uint64_t bad = 0;
  for (int t = 0; t < parts; ++t) bad |= bad_of[static_cast<std::size_t>(t)];
  return bad == 0;
}

// v += dv(k), x += h v over the 3n values, split in ranges at 2+ threads; whether every value
// stayed finite and the largest speed. Elementwise, with an OR and a max as reductions: bitwise
// equal at any thread count.
struct Advanced {
  bool finite;
  double max_speed;
};
template <class Dv>
Advanced advance(std::span<double> x_all, std::span<double> v_all, double h, const Dv& dv) {
  const std::size_t n3 = x_all.size();
  const int parts = detail::parts_for(n3, vector_grain);
  std::array<std::uint64_t, max_threads> bad_of{}, speed_of{};
  detail::run_parts(parts, [&](int t) {
    double* __restrict x = x_all.data();  // a lambda's captures lose __restrict: the loop would not vectorise
    double* __restrict v = v_all.data();
    std::uint64_t bad = 0, speed = 0;
    const std::size_t k1 = detail::range_begin(n3, parts, t + 1);
    for (std::size_t k = detail::range_begin(n3, parts, t); k < k1; ++k) {
      v[k] += dv(k);
      x[k] += h * v[k];
      bad |= inf_or_nan(v[k]) | inf_or_nan(x[k]);
      speed = std::max(speed, abs_bits(v[k]));
    }
    bad_of[static_cast<std::size_t>(t)] = bad;
    speed_of[static_cast<std::size_t>(t)] = speed;
  });
  std::uint64_t bad = 0, speed = 0;
  for (int t = 0; t < parts; ++t) {
    bad |= bad_of[static_cast<std::size_t>(t)];
    speed = std::max(speed, speed_of[static_cast<std::size_t>(t)]);
  }
  return {bad == 0, std::bit_cast<double>(speed)};
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
                        detail::format_number(p[0]) + ", " + detail::format_number(p[1]) + ", " + detail::format_number(p[2]) + "); the step was not taken";
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

// ------------------------------------------------------------------ SymplecticEuler

SymplecticEuler::SymplecticEuler(SymplecticEulerOptions options) : opt_(options) {}

void SymplecticEuler::reset() {
  bound_ = StableStep{std::numeric_limits<double>::quiet_NaN()};
  watchdog_.reset();
}

SymplecticEuler::History SymplecticEuler::history(const System& sys) const {
  return {bound_, bound_version_ == sys.version(), steps_, bound_step_, watchdog_.state(sys)};
}

void SymplecticEuler::restore(const System& sys, const History& h) {
  bound_ = h.bound;
  // a bound taken before the last edit is recomputed at the next step, as it would have been
  bound_version_ = h.bound_current ? sys.version() : sys.version() + 1;
  steps_ = h.steps;
  bound_step_ = h.bound_step;
  watchdog_.restore(sys, h.watchdog);
}

StepReport SymplecticEuler::step(System& sys, double h) {
  check_step(h, "SymplecticEuler::step");
  sys.require_no_angles("SymplecticEuler::step");
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
      throw StabilityError("SymplecticEuler::step: h = " + detail::format_number(h) + " s is not below the stable-step bound " +
                               detail::format_number(bound_.h_max) + " s (omega_max <= " + detail::format_number(std::sqrt(bound_.stiffness_bound)) +
                               " rad/s from node " + std::to_string(bound_.stiffness_node) + ", damping rate <= " +
                               detail::format_number(bound_.damping_bound) + " 1/s). Use a smaller step or LinearlyImplicitEuler, or "
                               "set enforce_stable_step = false; the state is unchanged.",
                           h, bound_.h_max);
    }
  }
  const bool watch = opt_.health.energy_check_interval > 0;
  if (watch) watchdog_.baseline_if_needed(sys);
  sys.compute_forces();
  NodeTable& nodes = sys.nodes();
  if (opt_.health.check_finite) check_finite(nodes, "SymplecticEuler::step");
  double max_speed = 0;
  bool finite = true;  // else the next step's check names the value; energies of a NaN state mean nothing
  SlaveNodes& slaves = sys.slaves();  // T-junctions: forces to their masters, masses lumped there
  if (!slaves.empty()) slaves.pass_forces(nodes.f());
  {
    const double* __restrict f = nodes.f().data();
    const double* __restrict im = (slaves.empty() ? nodes.inverse_mass_dof() : slaves.inverse_mass_dof(nodes)).data();
    const Advanced a = advance(nodes.x(), nodes.v(), h, [f, im, h](std::size_t k) { return h * im[k] * f[k]; });
    if (a.finite) nodes.mark_state_finite();
    finite = a.finite;
    max_speed = a.max_speed;
  }
  if (!slaves.empty()) slaves.after_step(nodes);
  ++steps_;
  sys.step_accepted();
  if (watch && finite)
    if (auto blowup = watchdog_.after_step(sys, opt_.health, steps_, max_speed)) {
      // An unguarded run has no bound yet: computing one after every cut would cost several
      // steps for a message. Taken now, in the diverging state, it is the bound of a stiffer
      // configuration (stretched springs add their geometric stiffness), so the suggestion errs
      // on the safe side.
      const bool guarded = opt_.enforce_stable_step && !std::isnan(bound_.h_max);
      const StableStep bound = guarded ? bound_ : sys.stable_step();
      const double suggested = 0.9 * bound.h_max;
      throw BlowupError("SymplecticEuler::step: " + blowup->message + ". The step h = " + detail::format_number(h) +
                            " s is too large for the scheme: the stable-step bound " +
                            (guarded ? "checked before this step" : "in the state the run stopped in") + " is " +
                            detail::format_number(bound.h_max) + " s; suggested step " + detail::format_number(suggested) + " s",
                        blowup->node, "energy", steps_, suggested);
    }
  return rep;
}

// ------------------------------------------------------------------ LinearlyImplicitEuler

LinearlyImplicitEuler::LinearlyImplicitEuler(ImplicitEulerOptions options) : opt_(options) {}

void LinearlyImplicitEuler::reset() {
  std::fill(dv_.begin(), dv_.end(), 0.0);
  if (solver_) solver_->reset();
  watchdog_.reset();
}

LinearlyImplicitEuler::History LinearlyImplicitEuler::history(const System& sys) const {
  History h{std::vector<double>(dv_.begin(), dv_.end()), steps_, watchdog_.state(sys), {}};
  if (solver_ && sys.topology_key() == solved_topology_) h.solver = solver_->state();
  return h;
}

void LinearlyImplicitEuler::restore(System& sys, const History& h) {
  // A warm start of another size is from before the topology changed (a refinement after the
  // last solve): the next step drops it, as it would have dropped it in the run it came from.
  if (h.warm_start.size() % 3 != 0)
    throw InputError("LinearlyImplicitEuler::restore: the warm start has " + std::to_string(h.warm_start.size()) +
                     " values, not 3 per node");
  // the work arrays are sized by the next step; an empty warm start leaves them to it
  dv_.assign(h.warm_start.begin(), h.warm_start.end());
  b_.assign(dv_.size(), 0.0);
  kv_.assign(dv_.size(), 0.0);
  free_.assign(dv_.size(), 0.0);
  mass3_.assign(dv_.size(), 0.0);
  steps_ = h.steps;
  watchdog_.restore(sys, h.watchdog);
  if (h.solver.factored.empty() && !h.solver.refresh_due) return;
  make_solver(sys.nodes().size());
  solver_->restore(sys.matrix(), h.solver);
  solved_topology_ = sys.topology_key();
}

void LinearlyImplicitEuler::make_solver(Index nodes) {
  if (solver_ && solver_asked_ == opt_.solver) return;
  solver_ = solve::make_solver(opt_.solver, {}, nodes);
  solver_asked_ = opt_.solver;
}

StepReport LinearlyImplicitEuler::step(System& sys, double h) {
  check_step(h, "LinearlyImplicitEuler::step");
  sys.require_no_angles("LinearlyImplicitEuler::step");
  if (!(opt_.cg_tolerance > 0 && std::isfinite(opt_.cg_tolerance)))
    throw InputError("LinearlyImplicitEuler::step: cg_tolerance must be finite and > 0, got " + detail::format_number(opt_.cg_tolerance));
  if (opt_.cg_max_iterations < 1)
    throw InputError("LinearlyImplicitEuler::step: cg_max_iterations must be >= 1, got " +
                     std::to_string(opt_.cg_max_iterations));
  detail::require_symmetric_jacobians(sys, opt_.jacobian, "LinearlyImplicitEuler::step");
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
    mass3_.assign(n3, 0.0);
  }
  make_solver(n);
  solve::SolverOptions& so = solver_->options();
  so.tolerance = opt_.cg_tolerance;
  so.max_iterations = opt_.cg_max_iterations;
  if (!(opt_.cg_absolute_tolerance >= 0 && std::isfinite(opt_.cg_absolute_tolerance)))
    throw InputError("LinearlyImplicitEuler::step: cg_absolute_tolerance must be finite and >= 0, got " +
                     detail::format_number(opt_.cg_absolute_tolerance));
  if (!(opt_.cg_absolute_acceleration >= 0 && std::isfinite(opt_.cg_absolute_acceleration)))
    throw InputError("LinearlyImplicitEuler::step: cg_absolute_acceleration must be finite and >= 0, got " +
                     detail::format_number(opt_.cg_absolute_acceleration));
  // the tighter floor: a velocity error, and a force imbalance that does not grow as h shrinks
  so.absolute_tolerance = std::min(opt_.cg_absolute_tolerance, opt_.cg_absolute_acceleration * h);
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
  // 3) b = h (F₀ + h ∂F/∂P V₀); ΔV = 0 on fixed axes (their velocity is prescribed). With the
  // masses, node by node, split in ranges (elementwise: the same at any count).
  const auto mass = nodes.masses();
  const auto fixed = nodes.fixed_masks();
  const auto f = nodes.f();
  const int parts = detail::parts_for(n3, vector_grain);
  detail::run_parts(parts, [&](int t) {
    for (auto i = static_cast<Index>(detail::range_begin(n, parts, t)); i < detail::range_begin(n, parts, t + 1); ++i) {
      double* diagonal = A.block_data(A.diagonal(i));
      for (unsigned a = 0; a < 3; ++a) {
        const std::size_t k = 3 * std::size_t{i} + a;
        diagonal[4 * a] += mass[i];
        free_[k] = ((fixed[i] >> a) & 1u) ? 0.0 : 1.0;
        mass3_[k] = mass[i];
        b_[k] = h * (f[k] + h * kv_[k]);
        if (!opt_.warm_start || free_[k] == 0.0) dv_[k] = 0.0;
      }
    }
  });
  solve::SolveReport sr;
  try {
    if (slaves.reduces()) {
      // T-junctions: block-Jacobi CG on the reduced system WᵀAW, preconditioned by its own
      // diagonal blocks (the layer's backends take the full pattern; a reduced pattern for them
      // is future work).
      AlignedVector<double> precond(9 * static_cast<std::size_t>(A.size()));
      slaves.reduced_block_jacobi(A, free_, precond);
      const CgResult cg = slaves.solve_reduced(A, b_, dv_, free_, precond, opt_.cg_tolerance, opt_.cg_max_iterations);
      sr.iterations = cg.iterations;
      sr.relative_residual = cg.relative_residual;
      sr.converged = cg.converged;
    } else {
      solver_->set_coordinates(nodes.x());
      sr = solver_->solve(A, b_, dv_, free_, mass3_);
      solved_topology_ = sys.topology_key();
    }
  } catch (const SolverError& e) {
    std::fill(dv_.begin(), dv_.end(), 0.0);
    throw SolverError("LinearlyImplicitEuler::step " + std::to_string(steps_ + 1) + ": " + e.what() +
                          " (compression with clamp_compression = false?); the state is unchanged",
                      e.iterations(), e.residual());
  }
  rep.solve = sr;
  rep.cg_iterations = sr.iterations;
  rep.cg_relative_residual = sr.relative_residual;
  rep.cg_converged = sr.converged;
  if (!sr.converged && opt_.throw_on_cg_failure) {
    std::fill(dv_.begin(), dv_.end(), 0.0);
    throw SolverError("LinearlyImplicitEuler::step " + std::to_string(steps_ + 1) + ": the " +
                          std::string(solve::to_string(sr.backend)) + " solve stopped after " +
                          std::to_string(sr.iterations) + " iterations at relative residual " +
                          detail::format_number(sr.relative_residual) + " (tolerance " + detail::format_number(opt_.cg_tolerance) + ", limit " +
                          std::to_string(opt_.cg_max_iterations) + " iterations); the state is unchanged",
                      sr.iterations, sr.relative_residual);
  }

  // 4) V₁ = V₀ + ΔV, P₁ = P₀ + h V₁
  double max_speed = 0;
  bool finite = true;  // else the next step's check names the value; energies of a NaN state mean nothing
  {
    const double* __restrict dv = dv_.data();
    const Advanced a = advance(nodes.x(), nodes.v(), h, [dv](std::size_t k) { return dv[k]; });
    if (a.finite) nodes.mark_state_finite();
    finite = a.finite;
    max_speed = a.max_speed;
  }
  if (!slaves.empty()) slaves.after_step(nodes);
  ++steps_;
  sys.step_accepted();
  if (watch && finite)
    if (auto blowup = watchdog_.after_step(sys, opt_.health, steps_, max_speed)) {
      // No stability bound exists for this scheme; its energy grows when the linearisation
      // fails (fast rotation, large strain), which a smaller step makes smaller.
      const double suggested = h / 10;
      throw BlowupError("LinearlyImplicitEuler::step: " + blowup->message + ". The linearised step failed at h = " +
                            detail::format_number(h) + " s; suggested step " + detail::format_number(suggested) +
                            " s, or the momentum-conserving integrator for fast rotations",
                        blowup->node, "energy", steps_, suggested);
    }
  return rep;
}

}  // namespace sewn::physics
