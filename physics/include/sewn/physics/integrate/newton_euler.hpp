#pragma once
// NewtonEuler: backward Euler as an incremental potential (PHYSICS_NOTES §3.4). One step of
// size h finds
//     q_{n+1} = argmin Φ(q),  Φ(q) = (1/2h²)(q - q̂)ᵀM(q - q̂) + E(q) + D(q),  q̂ = q_n + h v_n,
// then sets v_{n+1} = (q_{n+1} - q_n)/h. E is the sum of the terms' potentials (external
// fields such as gravity included: that is the -f_extᵀq part). Velocity-dependent forces
// (MassDamping, spring damping, friction on obstacles) enter through the terms' dissipation
// potentials (ForceTerm::dissipation): D(q) = h Σ Ψ(x_n, v), v = (q - q_n)/h, the positions
// lagged at the step's start (a spring's damping direction, friction's normal force frozen
// as IPC does), so that ∂D/∂q = -F_d(x_n, v) exactly; for a linear damping F_d = -Cv it is the
// Rayleigh potential (1/2h)(q - q_n)ᵀC(q - q_n). Newton's matrix takes the damping's ∂F/∂v at
// q rather than x_n (one assembly; they differ only where a spring turns within the step). A
// term whose forces depend on velocity without a dissipation potential is refused
// (InputError): Φ would not be its integral.
//
// Newton: g = M(q - q̂)/h² - F(q, v), H = M/h² - ∂F/∂x - (1/h)∂F/∂v with every element Hessian
// PSD-projected (JacobianOptions::project_element_hessians, clamp_compression); H p = -g is
// solved on the free axes (fixed axes follow their prescribed velocity, q = q_n + h v_n, and
// are filtered); a step turning an angle DOF by more than max_angle_step is scaled down to it,
// and so is a step longer than some term allows one trial (ForceTerm::step_fraction: a point
// joint's twist and bend); Armijo backtracking α = 1, ½, ... until Φ(q + αp) ≤ Φ(q) + c α gᵀp; stop
// when |p|∞/h < velocity_tolerance, an angle's update counted as the distance it moves its
// material (AngleTable::lengths() × Δθ: a rod's section radius of gyration, a Morley edge's
// triangle height), not in radians.
//
// The linear solve is the single function solve_linear() (block-Jacobi PCG on the block
// matrix; PCG preconditioned by a kept CHOLMOD factorization; or a sparse direct solve:
// CHOLMOD's supernodal Cholesky through solve::LinearSolver when the build has it, else, or
// once CHOLMOD finds the matrix not positive definite, Eigen's SimplicialLDLT on its sparse copy).
//
// Failure (no descent direction or line search exhausted, too many iterations, a non-finite
// energy, gradient or state) throws NewtonError naming what failed, with the node table
// unchanged (positions and velocities as before the step).
//
// Initial guess: q̂ on the fixed axes (their prescribed motion) and q_n + α h v_n on the free
// ones, α ≤ 1 the largest fraction of the path q_n → q̂ (every axis) the terms allow
// (ForceTerm::step_fraction): a knocked body's
// h·v_n can bend a joint further in one guess than its incremental twist can follow (the toy
// ball's spring end edge, 1.7 mm long, moved 17 mm). Φ and its minimiser do not depend on it.
//
// Condensed angles (AngleTable::set_condensed, a rod's quasi-static twist): in the linear solve,
// so the position step is the reduced energy's Newton step, then dropped from p (their term
// solves them at every trial point; their update still counts in the stopping test, as the
// distance the next solve will turn them).
//
// Angle DOFs: the step works on flat arrays of dof_count() entries with a per-DOF inertia and
// a per-DOF free flag, all built in prepare(): the 3n positions, then System::angles() (a
// rod's twist angle per edge, inertia J ≥ 0, free unless fixed), padded to whole blocks
// (AngleLayout); a System without angles has dof_count() = 3n and pays nothing.
//
// After an accepted step the integrator calls System::step_accepted(), so history frozen
// within the step (rods' time-parallel frames, connections' accepted twist) moves on.
//
// Cost per Newton iteration: one Jacobian assembly (element Hessians + projections), one
// linear solve (CG: iterations × one block-sparse product; LDLT: one numeric factorisation,
// the symbolic one cached per pattern; kept-factorization PCG: a few iterations of two
// triangular solves each, a factorization now and then) and, per line-search trial, one energy
// and one force evaluation (two force evaluations when some term depends on velocity). The
// first trial (α = 1) evaluates the forces with the energy: it is accepted nearly always, and
// the accepted point's gradient is then not evaluated again.

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "sewn/physics/aligned.hpp"
#include "sewn/physics/cg.hpp"
#include "sewn/physics/errors.hpp"
#include "sewn/physics/system.hpp"
#include "sewn/physics/solve/linear_solver.hpp"

namespace sewn::physics::integrate {

enum class LinearSolver {
  cg,    ///< block-Jacobi PCG on the block matrix to a relative tolerance (inexact Newton)
  ldlt,  ///< sparse direct: CHOLMOD when built, else Eigen SimplicialLDLT (exact; symbolic step cached)
  /// CG to cg_tolerance preconditioned by a CHOLMOD factorization kept across Newton iterations
  /// and steps (solve::Backend::cholmod_pcg, refreshed when CG slows down): a factorization costs
  /// tens of CG iterations on a large shell (the umbrella), and successive Newton matrices differ
  /// little. Projected Hessians only (exact_hessian_first is ignored, as with cg). Needs CHOLMOD.
  cholmod_pcg,
};

struct NewtonEulerOptions {
  double velocity_tolerance = 1e-6;  ///< m/s: converged when |p|∞/h is below it (an angle's update counted as AngleTable::lengths() × Δθ)
  int max_iterations = 50;
  int max_line_search = 40;          ///< halvings of α before "no descent"
  double armijo = 1e-4;              ///< c of the sufficient-decrease test
  LinearSolver solver = LinearSolver::cg;
  double cg_tolerance = 1e-4;        ///< η: relative residual of each Newton system
  /// With cholmod_pcg, > cg_tolerance: inexact Newton, each system solved to a forcing term
  /// η_k in [cg_tolerance, cg_forcing_max] (Eisenstat-Walker: this loose at the first
  /// iteration, tightening with the gradient's decrease), and a step that passes the stopping
  /// test with η_k > cg_tolerance is solved on to cg_tolerance before it is taken. 0: every
  /// system to cg_tolerance.
  double cg_forcing_max = 0.0;
  int cg_max_iterations = 5000;
  /// With the direct solve (ldlt): each iteration first factors the exact Hessian (no element
  /// projection) and keeps its step when the factorization finds the matrix positive definite
  /// and the step is a descent direction; otherwise it assembles the projected Hessian and
  /// solves again. Near an equilibrium the exact Hessian gives Newton's quadratic convergence
  /// where the projected one converges linearly (a bent helix's indefinite bend-twist
  /// stencils, compressed membranes). Ignored with CG (which cannot tell).
  bool exact_hessian_first = true;
  /// rad: a trust region on angle DOFs. A Newton step that turns some angle by more is scaled
  /// as a whole until none turns by more than this, before the line search. The quadratic
  /// model of a rod's twist is good for fractions of a radian only: a linearised helical
  /// spring asks its twist angles for 15 rad in one iteration, which crosses the reference
  /// twist's 2π branch (an energy jump the line search cannot get past) and the connections'
  /// guard. π/4, as the rods' static solve. No effect on a system without angles.
  double max_angle_step = 0.7853981633974483;
};

/// What a step did.
struct NewtonReport {
  int iterations = 0;         ///< Newton iterations (linear solves)
  int line_search_steps = 0;  ///< halvings of α, summed over iterations
  int linear_iterations = 0;  ///< CG iterations, summed (0 with LDLT)
  int steepest_fallbacks = 0; ///< iterations whose solve gave no descent and used -D⁻¹g instead
  int projected_retries = 0;  ///< iterations whose exact Hessian was indefinite (exact_hessian_first)
  int angle_step_limits = 0;  ///< iterations whose step was shortened by max_angle_step
  int term_step_limits = 0;   ///< iterations whose step a term shortened (ForceTerm::step_fraction)
  double guess_fraction = 1.0; ///< α of the initial guess q_n + α h v_n on the free axes
  int forcing_refinements = 0; ///< loose solves (cg_forcing_max) solved on to cg_tolerance before the stopping test
  /// α the line search took at the iteration before the one that stopped (1: none). Well below 1,
  /// Newton was still far from the solution one iteration before the step test passed: its steps
  /// can be short there because the line search or curvature keeps them so, not because it is done.
  double last_alpha = 1.0;
  double step_velocity = 0.0; ///< |p|∞/h of the last iteration, m/s (angles as length × Δθ)
  double phi_decrease = 0.0;  ///< Φ(q̂) - Φ(q_{n+1}) ≥ 0
};

/// A step that failed; the node table is unchanged. reason() names the failure.
class NewtonError : public SolverError {
 public:
  enum Reason { no_descent, too_many_iterations, non_finite };
  NewtonError(const std::string& what, Reason r, const NewtonReport& rep)
      : SolverError(what, rep.iterations, rep.step_velocity), reason_(r), report_(rep) {}
  [[nodiscard]] Reason reason() const { return reason_; }
  [[nodiscard]] const NewtonReport& report() const { return report_; }

 private:
  Reason reason_;
  NewtonReport report_;
};

class NewtonEuler {
 public:
  explicit NewtonEuler(NewtonEulerOptions options = {});
  ~NewtonEuler();
  NewtonEuler(NewtonEuler&&) noexcept;
  NewtonEuler& operator=(NewtonEuler&&) noexcept;

  /// Advances sys by h > 0. Throws InputError on a bad h, NewtonError (state unchanged) on
  /// failure. Allocation only when the DOF count or the pattern changed.
  NewtonReport step(System& sys, double h);
  [[nodiscard]] NewtonEulerOptions& options() { return opt_; }
  /// Φ at q (positions, then angles as in dof_count()) for the step being prepared (tests:
  /// monotone decrease). Valid after a step; evaluates with that step's q_n, v_n and h.
  [[nodiscard]] double incremental_potential(const System& sys, std::span<const double> q);

  /// What a step reads from earlier steps besides the system's state, for a checkpoint:
  /// cholmod-pcg's factorization of an earlier matrix and its refresh rule (solve::SolverState:
  /// which matrix was factored decides every later iterate), and whether CHOLMOD's direct
  /// factorization once failed (ldlt uses the simplicial LDLᵀ from then on).
  struct History {
    solve::SolverState solver;
    bool direct_failed = false;
  };
  /// The solver's state is left out (empty) when the topology changed since its last solve:
  /// the next solve starts afresh on the new pattern anyway.
  [[nodiscard]] History history(const System& sys) const;
  /// Takes up a history of a run of the same system (its topology rebuilt as it was). Throws
  /// InputError if the solver state does not fit the system's pattern, SolverError if the
  /// stored matrix cannot be factored. O(factorization).
  void restore(System& sys, const History& h);

 private:
  struct LdltCache;
  void prepare(System& sys, double h);
  // Throws InputError if t's forces at x_n change with the velocity (t has no dissipation potential).
  void probe_velocity_dependence(const System& sys, const ForceTerm& t);
  // The state view of flat arrays q, vel (positions, then angles).
  [[nodiscard]] StateView view(const System& sys, std::span<const double> q, std::span<const double> vel) const;
  [[nodiscard]] std::string describe_dof(std::size_t k) const;
  // Φ and its gradient at q (velocities (q - q_n)/h); returns Φ, fills g_. O(elements).
  double evaluate(const System& sys, std::span<const double> q, bool want_gradient);
  // H into sys.matrix(), the element Hessians PSD-projected or exact.
  void assemble(System& sys, bool project);
  // Solves H p = -g on the free axes into p_; returns CG iterations (0 for LDLT). With
  // need_definite (direct solves only), returns -1 with p_ = 0 when H is not positive definite.
  int solve_linear(const BlockMatrix& A, bool need_definite = false);
  // Scales p_ (and its slope gᵀp and |p|∞) so no angle turns by more than max_angle_step.
  void limit_angle_step(double& slope, double& pmax, NewtonReport& rep);
  // The smallest ForceTerm::step_fraction of the terms for a change dq from q.
  [[nodiscard]] double term_step_fraction(const System& sys, std::span<const double> q, std::span<const double> dq) const;
  // q_ = the initial guess (see the header comment).
  void predict(const System& sys, NewtonReport& rep);
  // Scales p_ and its slope gᵀp to the fraction of it the terms allow from q_.
  void limit_term_step(const System& sys, double& slope, NewtonReport& rep);
  // The cholmod-pcg backend, made on first use.
  solve::LinearSolver& kept_pcg();
  // solve_linear() for LinearSolver::cholmod_pcg; returns the CG iterations.
  // Its relative tolerance given; starts from p_ as it is.
  int solve_kept_pcg(const BlockMatrix& A, double tolerance);
  // p_ = -D⁻¹g (D: A's diagonal), always a descent direction; its slope gᵀp and |p|∞.
  void steepest_descent(const BlockMatrix& A, double& slope, double& pmax);
  // Zeroes p_ on condensed angles (AngleTable::set_condensed: their term solves them at every
  // evaluation) and takes their part out of the slope gᵀp.
  void drop_condensed(double& slope);
  // max over the DOFs of length × |p|: how far the step moves any material point.
  [[nodiscard]] double largest_move() const;
  [[nodiscard]] double gradient_norm() const;
  // The relative CG tolerance of this iteration's solve (cg_forcing_max).
  [[nodiscard]] double forcing_term(double g_now, double g_prev, bool first) const;
  [[nodiscard]] std::size_t dof_count() const { return inertia_.size(); }

  NewtonEulerOptions opt_;
  double h_ = 0.0;
  std::size_t n3_ = 0;  // position entries; angles follow
  double eta_ = 0.0;  // this iteration's relative CG tolerance (forcing_term)
  AlignedVector<double> xn_, vn_, qhat_, q_, trial_, inertia_, free_, condensed_, length_, g_, f_, fv_, f0_, vel_, p_, rhs_, precond_, zeros_;
  CgWorkspace ws_;
  std::unique_ptr<LdltCache> ldlt_;
  std::uint64_t kept_topology_ = ~std::uint64_t{0};  // the system's topology at the kept factor's last solve
};

}  // namespace sewn::physics::integrate
