#pragma once
// Time integrators for a System (PHYSICS_NOTES §1.5-1.6):
//   SymplecticEuler        V ← V + h M⁻¹F(P,V), then P ← P + h V (the seed's semi-implicit
//                          scheme), refused above the stable-step bound unless opted out;
//   LinearlyImplicitEuler  (M - h∂F/∂V - h²∂F/∂P) ΔV = h (F₀ + h ∂F/∂P V₀), V ← V + ΔV,
//                          P ← P + h V, solved with filtering by the solver layer
//                          (solve/linear_solver.hpp: block-Jacobi PCG, CHOLMOD, CHOLMOD-PCG).
// Fixed axes keep their velocity (0 unless prescribed: kinematic). Both check the state
// before using it: a non-finite position, velocity or force stops the step with a
// BlowupError naming the node, leaving the state as it was; an energy watchdog
// (integrate/watchdog.hpp) stops runs whose kinetic + internal energy outgrows what the
// initial state and external fields can supply, within a few steps of a divergence's start,
// with the step, the fastest node and a step to retry with.

#include <cstdint>
#include <limits>
#include <memory>
#include <vector>

#include "sewn/physics/aligned.hpp"
#include "sewn/physics/cg.hpp"
#include "sewn/physics/solve/linear_solver.hpp"
#include "sewn/physics/integrate/watchdog.hpp"
#include "sewn/physics/system.hpp"

namespace sewn::physics {

/// What a step did. Semi-implicit steps leave the solver fields at their defaults.
struct StepReport {
  int cg_iterations = 0;              ///< = solve.iterations
  double cg_relative_residual = 0.0;  ///< = solve.relative_residual
  bool cg_converged = true;           ///< = solve.converged
  solve::SolveReport solve;           ///< the linear solve's full report (backend, factorizations, times)
  bool pattern_rebuilt = false;
  double stable_step = std::numeric_limits<double>::quiet_NaN();  ///< bound in force (semi-implicit)
};

struct SymplecticEulerOptions {
  /// Refuse (StabilityError) a step h ≥ the stable-step bound. Opt out for cost benchmarks
  /// or when stability is ensured otherwise: an unguarded run then evaluates the bound (a
  /// Gershgorin pass costing 5–10 steps of a spring grid) only to suggest a step when the
  /// watchdog stops it, never after a cut.
  bool enforce_stable_step = true;
  /// Steps between re-evaluations of the bound (it is also re-evaluated whenever the system
  /// changes). It depends on the state through the spring directions and stretches.
  int stable_step_recheck_interval = 100;
  HealthOptions health;
};

class SymplecticEuler {
 public:
  explicit SymplecticEuler(SymplecticEulerOptions options = {});
  /// Advances sys by h > 0. Throws InputError on a bad h, StabilityError (state unchanged)
  /// if h is above the bound, BlowupError on a non-finite state (unchanged) or an energy
  /// blow-up. Cost: one force evaluation and one pass over the nodes.
  StepReport step(System& sys, double h);
  /// The bound computed most recently (h_max = NaN before the first checked step).
  [[nodiscard]] const StableStep& last_stable_step() const { return bound_; }
  [[nodiscard]] SymplecticEulerOptions& options() { return opt_; }
  /// Forgets the cached bound and the energy baseline.
  void reset();

  /// Everything a step reads from earlier steps (the cached bound, the step counters, the
  /// watchdog), so that a run restored from a checkpoint takes the same steps.
  struct History {
    StableStep bound{};
    bool bound_current = false;  ///< taken at the system's present version
    std::uint64_t steps = 0, bound_step = 0;
    EnergyWatchdog::State watchdog;
  };
  [[nodiscard]] History history(const System& sys) const;
  void restore(const System& sys, const History& h);

 private:
  SymplecticEulerOptions opt_;
  StableStep bound_{std::numeric_limits<double>::quiet_NaN()};
  std::uint64_t bound_version_ = 0;
  std::uint64_t steps_ = 0, bound_step_ = 0;
  EnergyWatchdog watchdog_;
};

struct ImplicitEulerOptions {
  /// The linear solver (solve/linear_solver.hpp); `automatic` starts with
  /// block-Jacobi CG and moves to a kept-factor PCG when its iterations show a factor pays
  /// (linear_solver.hpp).
  solve::Backend solver = solve::Backend::automatic;
  double cg_tolerance = solve::default_tolerance;  ///< relative residual ‖S(b - AΔV)‖/‖Sb‖
  /// Absolute floor of the residual as a velocity, m/s (solve::SolverOptions::absolute_tolerance):
  /// a body at rest stops at it instead of chasing the round-off of a vanishing right-hand side.
  /// A step of h uses the smaller of this and cg_absolute_acceleration · h.
  double cg_absolute_tolerance = solve::default_absolute_tolerance;
  /// The floor as an acceleration, m/s²: a velocity error of at most this times h, i.e. a force
  /// imbalance of at most this times the mass on every free axis, whatever the step. A fixed
  /// velocity floor alone loosens as h shrinks: at h = 10 µs 1e-9 m/s is a force error of
  /// 1e-4 m/s² (the 32³ cube's error after 10 steps 25× the floorless solve's; docs/solvers.md).
  double cg_absolute_acceleration = solve::default_absolute_acceleration;
  int cg_max_iterations = solve::default_max_iterations;
  bool warm_start = true;       ///< start CG from the previous step's ΔV
  /// Throw SolverError (state unchanged) when the solve misses its tolerance; if false the step
  /// is applied and StepReport::cg_converged is false. A matrix that is not positive definite
  /// always throws SolverError naming the step (state unchanged).
  bool throw_on_cg_failure = true;
  /// Simplifications of ∂F/∂x in the matrix (and in the ∂F/∂P·V₀ product, so the scheme is
  /// the linearised implicit Euler of that approximate Jacobian). CG needs a symmetric matrix.
  JacobianOptions jacobian;
  HealthOptions health;
};

class LinearlyImplicitEuler {
 public:
  explicit LinearlyImplicitEuler(ImplicitEulerOptions options = {});
  /// Advances sys by h > 0 (Baraff-Witkin form). Throws InputError on a bad h, bad solver
  /// options or a term whose matrix would not be symmetric, SolverError naming the step if the
  /// matrix is not positive definite or the solve misses its tolerance (unless opted out:
  /// then check the report), BlowupError as SymplecticEuler. Cost: one force and one Jacobian
  /// evaluation and one solve (jacobi: iterations × one block-sparse product; cholmod-pcg:
  /// iterations × (product + two triangular solves), plus a factorization when refreshed);
  /// no allocation once the work arrays are sized (they are resized after topology changes).
  [[nodiscard]] StepReport step(System& sys, double h);
  [[nodiscard]] ImplicitEulerOptions& options() { return opt_; }
  /// Forgets the warm start, the solver's factorizations and the energy baseline.
  void reset();

  /// What a step reads from earlier steps: the warm start (the last ΔV), the step counter,
  /// the watchdog, and what the solver keeps that changes results (cholmod-pcg's factorization
  /// of an earlier matrix: solve::SolverState).
  struct History {
    std::vector<double> warm_start;  ///< empty before the first step
    std::uint64_t steps = 0;
    EnergyWatchdog::State watchdog;
    solve::SolverState solver;
  };
  /// The solver's state is left out (empty) when the topology changed since the last solve:
  /// the next solve starts afresh on the new pattern anyway.
  [[nodiscard]] History history(const System& sys) const;
  /// Takes up a history of a run of the same system (its topology rebuilt as it was): builds
  /// the matrix pattern if the solver state needs it and hands that to the solver. A warm
  /// start of another size than sys's (taken before a topology change) is dropped by the next
  /// step, as the integrator it came from would have dropped it. Throws InputError if the warm
  /// start is not 3 values per node or the solver state does not fit the pattern, SolverError
  /// if its matrix cannot be factored.
  void restore(System& sys, const History& h);

 private:
  ImplicitEulerOptions opt_;
  AlignedVector<double> b_, dv_, kv_, free_, mass3_;
  std::unique_ptr<solve::LinearSolver> solver_;
  solve::Backend solver_asked_ = solve::Backend::automatic;
  std::uint64_t solved_topology_ = ~std::uint64_t{0};  // sys.topology_key() at the last solve
  void make_solver(Index nodes);  // solver_ of the backend asked for, if not made yet
  std::uint64_t steps_ = 0;
  EnergyWatchdog watchdog_;
};

}  // namespace sewn::physics
