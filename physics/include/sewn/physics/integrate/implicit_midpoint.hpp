#pragma once
// Implicit midpoint rule, solved by Newton's method (issue 17: a momentum-conserving implicit
// integrator). With x̄ = (x₀+x₁)/2 and v̄ = (v₀+v₁)/2:
//   M (v₁ − v₀) = h F(x̄, v̄),   x₁ = x₀ + h v̄.
// Unknown Δv = v₁ − v₀, so x̄ = x₀ + (h/2)v₀ + (h/4)Δv and v̄ = v₀ + Δv/2; the residual
//   r(Δv) = h F(x̄, v̄) − M Δv
// is driven to zero by Newton steps (M − (h²/4)∂F/∂x − (h/2)∂F/∂v) δ = r, Δv += δ, each solved
// by the filtered block-Jacobi CG (the symmetric Jacobian of JacobianOptions: a quasi-Newton
// step where springs are compressed).
//
// What it conserves: since x₁×v₁ − x₀×v₀ = x̄×(v₁−v₀), the change of angular momentum over a
// step is Σ x̄ × r: for forces that are central and sum to zero (springs, their viscosity) and a
// converged residual, linear and angular momentum are kept to the Newton tolerance, at any h.
// The rule is symplectic: the energy of a conservative system oscillates within a bound (of
// order (hω)² in the fast modes) and does not drift; it is exact for quadratic energies.
// What it loses: fast modes (hω ≫ 1) are not damped, they are aliased; there is no numerical
// dissipation, so only physical damping calms them. With nonlinear springs it is not
// unconditionally stable: a free cube spun at 100 rad/s with h = 10 ms (a rotation of 1 rad
// per step) gains energy until the watchdog stops it (Simo & Tarnow 1992 describe this for
// nonlinear elastodynamics); the springs' discrete-gradient form (the default) removes that.
// Newton may miss at such a rotation per step: the step is then split into sub-steps
// (ImplicitMidpointOptions::max_step_halvings). Fixed axes keep their velocity.

#include <cstdint>
#include <span>
#include <string>

#include "sewn/physics/aligned.hpp"
#include "sewn/physics/cg.hpp"
#include "sewn/physics/integrate/watchdog.hpp"
#include "sewn/physics/integrators.hpp"
#include "sewn/physics/system.hpp"

namespace sewn::physics {

struct ImplicitMidpointOptions {
  /// Newton stops when ‖r‖₂ ≤ newton_tolerance · (‖M v₀‖₂ + ‖M Δv‖₂ + ‖h F(x̄, v̄)‖₂): momentum
  /// changes per step are then below this fraction of the momentum and impulses in play.
  double newton_tolerance = 1e-13;
  /// Newton also stops when a step no longer halves the residual (round-off) and it is below
  /// stagnation_tolerance · that scale or roundoff_factor · the residual's round-off estimate
  /// (see roundoff_estimate()); above both that is a failed attempt.
  double stagnation_tolerance = 1e-10;
  /// How far above the springs' round-off estimate a stagnating residual is still accepted. The
  /// scale above is momentum and impulse, which a stiff body near rest barely has, while the
  /// round-off of its forces grows with E: on the 20×2×2 cantilever at E ≥ 1 GPa the residual
  /// stagnated at 2e-10 … 4e-8 of that scale and every step was refused. Measured there (E = 1 to
  /// 100 GPa, h = 1 and 10 ms, tests/physics/test_spin.cpp): Newton's last residual is 0.02 to
  /// 0.06 of the estimate, which is a bound more than an expectation; 1 leaves 16× of margin.
  double roundoff_factor = 1.0;
  int max_newton_iterations = 30;
  /// When Newton (or a CG solve in it) fails, the step is retried as two half steps, each of
  /// which may be halved again, up to this many times (2^max_step_halvings sub-steps). Each
  /// sub-step is a midpoint step, so the momenta and energy kept per step are kept over their
  /// sequence. Newton's matrix is the midpoint forces' Jacobian, not the discrete gradient's, and
  /// misses where a spring turns by ~1 rad in a step (a cube spun at 100 rad/s, h = 10 ms);
  /// half that turn converges. 0: fail at once. In [0, 20].
  int max_step_halvings = 5;
  /// CG relative residual of each Newton step: it sets how many Newton steps are needed, not
  /// the accuracy (the nonlinear residual is evaluated exactly).
  double cg_tolerance = 1e-8;
  int cg_max_iterations = 5000;
  /// Springs' elastic forces in discrete-gradient form (Gonzalez 1996): k(1 − 2l/(d₀+d₁))
  /// along x̄ⱼ − x̄ᵢ instead of k(1 − l/d̄) along it. Still central at the midpoint, so momenta are
  /// kept as before, and the work over the step is exactly −Δ(spring energy), so a conservative
  /// system keeps its energy to the Newton tolerance at any step (the energy-momentum method).
  /// False: the plain midpoint rule (see the header comment for where it fails).
  bool discrete_gradient_springs = true;
  /// The Newton matrix's Jacobian: that of the midpoint forces (exact for the plain rule, an
  /// approximation for the discrete gradient, to which it tends as the step shrinks).
  JacobianOptions jacobian;
  HealthOptions health;
};

/// Newton's cost, in StepReport terms: cg_iterations sums every Newton step's.
class ImplicitMidpoint {
 public:
  explicit ImplicitMidpoint(ImplicitMidpointOptions options = {});
  /// Advances sys by h > 0, in sub-steps where Newton needs them (max_step_halvings). Throws
  /// InputError on a bad h or option, SolverError (state unchanged) if Newton or a CG solve
  /// misses its tolerance even at the finest sub-step, BlowupError as the other integrators.
  /// Cost per Newton iteration: one force and one Jacobian evaluation and a CG solve; 2-5
  /// iterations are usual. No allocation once the work arrays are sized.
  [[nodiscard]] StepReport step(System& sys, double h);
  /// Newton iterations of the last step (all its sub-steps).
  [[nodiscard]] int last_newton_iterations() const { return newton_iterations_; }
  /// Sub-steps the last step took (1 when Newton converged at h), and how many times its
  /// finest sub-step was halved.
  [[nodiscard]] int last_substeps() const { return substeps_; }
  [[nodiscard]] int last_halvings() const { return finest_; }
  /// The largest ratio, over the last step's sub-steps, of Newton's final residual to the
  /// round-off estimate (how close to round-off Newton went).
  [[nodiscard]] double last_residual_over_roundoff() const { return residual_over_roundoff_; }
  /// What round-off alone leaves in the residual h F(x̄) − M Δv at positions x, for step h:
  /// h ε √(Σ_springs (k (‖x_i‖∞ + ‖x_j‖∞))²), each spring's force k(1 − l/d)(x_j − x_i) carrying
  /// an error of about k ε ‖x‖ from the rounding of the positions it subtracts (it grows with the
  /// coordinates, not with the spring's length or stretch). Springs only. O(springs).
  [[nodiscard]] static double roundoff_estimate(const System& sys, std::span<const double> x, double h);
  [[nodiscard]] ImplicitMidpointOptions& options() { return opt_; }
  /// Forgets the energy baseline.
  void reset() { watchdog_.reset(); }

  /// What a step reads from earlier steps (each step starts Newton from ΔV = 0): the step
  /// counter and the watchdog, so that a run restored from a checkpoint takes the same steps.
  struct History {
    std::uint64_t steps = 0;
    EnergyWatchdog::State watchdog;
  };
  [[nodiscard]] History history(const System& sys) const { return {steps_, watchdog_.state(sys)}; }
  void restore(const System& sys, const History& h) {
    steps_ = h.steps;
    watchdog_.restore(sys, h.watchdog);
  }

 private:
  // The one place a linear system is solved (A δ = b on the free axes, δ = 0 on fixed ones).
  CgResult solve(const BlockMatrix& A, std::span<const double> b, std::span<double> x);
  // Advances by h, as two halves (recursively) if Newton fails at h. False if it failed at the
  // finest sub-step (the state is then part-way: step() restores it).
  bool advance(System& sys, double h, int depth, StepReport& rep);
  // One midpoint step by Newton. False (state unchanged, failure_ set) if it did not converge.
  bool attempt(System& sys, double h, StepReport& rep);
  // Replaces, in the force array, each spring's elastic force at x̄ by its discrete gradient.
  void discrete_gradient(System& sys, double h) const;
  void restore(NodeTable& nodes) const;

  ImplicitMidpointOptions opt_;
  AlignedVector<double> x0_, v0_, dv_, r_, delta_, free_, precond_, x_start_, v_start_;
  CgWorkspace ws_;
  std::uint64_t steps_ = 0;
  int newton_iterations_ = 0;
  int substeps_ = 0, finest_ = 0;
  std::string failure_;  // why the last failed attempt failed
  double failure_residual_ = 0.0;
  double residual_over_roundoff_ = 0.0;
  EnergyWatchdog watchdog_;
};

}  // namespace sewn::physics
