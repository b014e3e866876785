#pragma once
// The solver layer: every implicit integrator solves its symmetric positive definite systems
// A x = b, assembled on the 3×3 block pattern (BlockMatrix), through one LinearSolver.
//
// How an integrator uses it (the linearly implicit Euler does exactly this, a Newton iteration
// does it once per iteration):
//   1. assemble A into sys.matrix() (the pattern is reused until the topology changes);
//   2. free_dof[k] = 1 on free axes, 0 on fixed ones;
//   3. put the prescribed values of the fixed axes (and a warm start on the free ones) in x;
//   4. report = solver.solve(A, b, x, free_dof).
// Fixed axes are filtered (PHYSICS_NOTES §1.5): x keeps its values there and the free axes
// solve S(b - A x) = 0, S = diag(free_dof). A solver keeps what it can reuse between calls
// (a symbolic analysis while A's pattern_version() is unchanged, a numeric factorization while
// it is accurate enough); a new pattern (a cut, a refinement) is noticed by itself.
//
// Backends (which exist in this build: available_backends()):
//   jacobi       block-Jacobi preconditioned CG, the reference: no set-up, O(iterations · blocks);
//   cholmod      sparse Cholesky (BlockCholesky below block_factor_flops, else SuiteSparse
//                CHOLMOD): symbolic analysis once per pattern,
//                numeric factorization whenever A's values changed, two triangular solves, and
//                up to 3 refinement passes (reported as iterations) while the residual misses
//                the tolerance (ill-conditioned matrices);
//   cholmod-pcg  CG preconditioned by a factorization of a recent A (BlockCholesky's below
//                block_factor_flops, else CHOLMOD's; solved in single precision), kept across
//                steps (and Newton iterations) while CG needs few iterations, refreshed when they grow;
//   hypre-pcg    the same CG and refresh rule, preconditioned by one V-cycle of hypre's BoomerAMG
//                (algebraic multigrid) set up on a recent A: set-up and V-cycle cost O(entries);
//   sa-pcg       the same CG and refresh rule, preconditioned by one V-cycle of our own
//                aggregation multigrid (coarse spaces from the rigid-body modes of aggregates of
//                neighbouring nodes; set_coordinates() gives the positions they need): set-up
//                O(entries of the Galerkin products), V-cycle 7 fine block-sparse products;
//   petsc        PETSc's KSP (CG, GAMG preconditioner) on every MPI rank of the program, each
//                rank owning a contiguous range of rows: the solve distributed, A assembled on
//                every rank (docs/scaling.md).
// hypre-pcg and petsc start MPI when the program did not (a serial program is one rank).
// Backend::automatic (measured: docs/solvers.md) starts with jacobi (default_backend()) at every
// size and switches for good to cholmod-pcg, where built in, after a solve of more than 120
// CG iterations on a model of at most 8000 nodes: a model stiff against its mass, small enough
// for a kept factorization; a new pattern starts over from jacobi. Its report and backend()
// name the backend that solves.

#include <cstdint>
#include <memory>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "sewn/physics/block_matrix.hpp"

namespace sewn::physics::solve {

enum class Backend { automatic, jacobi, cholmod, cholmod_pcg, hypre_pcg, petsc, sa_pcg };

/// "auto", "jacobi", "cholmod", "cholmod-pcg", "hypre-pcg", "petsc", "sa-pcg". O(1).
[[nodiscard]] std::string_view to_string(Backend b);
/// The inverse of to_string; throws InputError listing the names (and saying which are not
/// built in) for any other name. O(1).
[[nodiscard]] Backend parse_backend(std::string_view name);
/// The backends built in (jacobi always; the others when their library was found at build
/// time: SuiteSparse, hypre, PETSc). O(1).
[[nodiscard]] std::vector<Backend> available_backends();
[[nodiscard]] bool available(Backend b);

/// The CG iteration limit of the library and of the tool: the cantilever of bench/results/mss.md
/// at N = 16, h = 10 ms needs up to ~1300 block-Jacobi iterations a step, so 1000 failed there.
inline constexpr int default_max_iterations = 5000;
/// The relative residual every iterative solve stops at by default.
inline constexpr double default_tolerance = 1e-6;
/// The absolute floor of the residual, as a velocity (m/s, see SolverOptions).
inline constexpr double default_absolute_tolerance = 1e-9;
/// The implicit integrators' second floor, as an acceleration (m/s²): a step of h stops at a
/// velocity error of at most this times h (ImplicitEulerOptions::cg_absolute_acceleration).
inline constexpr double default_absolute_acceleration = 1e-6;

struct SolverOptions {
  /// Iterative backends stop when ‖S(b - Ax)‖ ≤ max(tolerance · ‖Sb‖, floor).
  double tolerance = default_tolerance;
  /// floor = absolute_tolerance · ‖S m‖, m the diagonal of A's mass part as passed in
  /// `mass_scale` (see solve()), i.e. the residual of a velocity error of absolute_tolerance
  /// m/s on every free axis. A body at rest has a right-hand side made of round-off, and a
  /// tolerance relative to it alone would chase that round-off; the floor stops there. 0: none.
  double absolute_tolerance = default_absolute_tolerance;
  int max_iterations = default_max_iterations;
  /// cholmod-pcg, hypre-pcg: the factorization (AMG hierarchy) is refreshed before the next
  /// solve once a solve cost more CG iterations than the mean cost per solve since the last
  /// refresh, the set-up counted in (its flops in iterations; docs/solvers.md), and at once,
  /// with a retry, if CG fails with a stale one. A value > 0 also refreshes once a solve needed
  /// more than this many iterations; 0: the cost rule alone.
  int refresh_iterations = 0;
  /// cholmod, cholmod-pcg: below this many flops of one numeric factorization the factor is
  /// BlockCholesky's (supernodal on the 3×3 blocks, block_cholesky.hpp), above it CHOLMOD's; 0:
  /// CHOLMOD's always. The count is the deciding analysis's: cholmod runs CHOLMOD's for it,
  /// cholmod-pcg BlockCholesky's, which then spares it CHOLMOD's. BlockCholesky measured faster
  /// on every matrix up to the N = 8 cantilever's 1.5e9 flops (docs/solvers.md); the default
  /// keeps CHOLMOD only beyond anything measured.
  double block_factor_flops = 1e10;
};

/// What one solve cost. Times are wall-clock milliseconds spent inside the solver.
struct SolveReport {
  Backend backend = Backend::jacobi;
  int symbolic_analyses = 0;  ///< 0 or 1 in this solve
  int factorizations = 0;     ///< numeric factorizations in this solve (0 when one was reused)
  int iterations = 0;         ///< CG iterations (0 for a direct solve)
  double relative_residual = 0.0;  ///< ‖S(b - Ax)‖ / ‖Sb‖ (0 if Sb = 0)
  double residual = 0.0;           ///< ‖S(b - Ax)‖
  bool converged = false;
  double analyse_ms = 0.0, factor_ms = 0.0, solve_ms = 0.0;
};

/// What a backend keeps from one solve to the next that changes later results, for a
/// checkpoint. cholmod-pcg (hypre-pcg) preconditions with a factorization (an AMG hierarchy) of
/// an earlier matrix, refreshed when CG slows down: which matrix that was decides every later
/// iterate, so the state holds its values and whether a refresh is due. jacobi and petsc keep
/// nothing (petsc sets its preconditioner up at every solve), and cholmod's kept factor changes
/// no result: it refactors whenever the values differ, and a factorization of equal values on
/// the analysis of an equal pattern is the same, bit for bit.
struct SolverState {
  std::vector<double> factored;  ///< cholmod-pcg, hypre-pcg: the filtered matrix's stored entries when factored (empty: no factor)
  bool refresh_due = false;      ///< cholmod-pcg, hypre-pcg: the next solve sets up afresh
  /// cholmod-pcg, hypre-pcg: solves and their CG iterations since the last set-up (the refresh rule's memory)
  std::uint64_t cycle_solves = 0, cycle_iterations = 0;
};

class LinearSolver {
 public:
  virtual ~LinearSolver() = default;
  [[nodiscard]] virtual Backend backend() const = 0;
  [[nodiscard]] SolverOptions& options() { return opt_; }
  [[nodiscard]] const SolverOptions& options() const { return opt_; }

  /// Solves the filtered system described above. A must be symmetric (blocks (i,j) = (j,i)ᵀ)
  /// and positive definite on the free axes. b, x, free_dof: 3·A.size() values; mass_scale:
  /// per-axis masses for the absolute floor (empty: the floor is not applied). Returns the
  /// report; converged = false if an iterative backend ran out of iterations (x then holds its
  /// last iterate). Throws SolverError if A is found not positive definite on the free axes:
  /// the CHOLMOD backends always find it, naming the node and axis of the failed pivot, with x
  /// unchanged; jacobi finds a negative diagonal entry (named, x unchanged) or a CG breakdown
  /// (x holds an iterate), but CG may also converge on an indefinite matrix without noticing.
  /// Throws InputError on sizes that do not match. Cost: see the backend list above. Not
  /// thread-safe per instance.
  virtual SolveReport solve(const BlockMatrix& A, std::span<const double> b, std::span<double> x,
                            std::span<const double> free_dof, std::span<const double> mass_scale = {}) = 0;
  /// Forgets every factorization and analysis (the next solve starts afresh). O(1).
  virtual void reset() {}
  /// The nodes' positions (3 per node), which sa-pcg's next set-up builds its rigid-body modes
  /// from (without them: translations only, a weaker coarse space); other backends ignore them.
  /// The integrators pass them before each solve. O(nodes).
  virtual void set_coordinates(std::span<const double> xyz) { (void)xyz; }
  /// See SolverState. O(entries of the kept factorization).
  [[nodiscard]] virtual SolverState state() const { return {}; }
  /// Takes up state() of a solver of this backend, for A's current pattern (the one it was
  /// taken on, rebuilt): cholmod-pcg (hypre-pcg) factors (sets up on) the stored values again, which gives the factor it
  /// had. Throws InputError if the values do not fit A's pattern (or are given to a backend
  /// that keeps none), SolverError if they cannot be factored; the solver then starts afresh
  /// at its next solve. O(one factorization).
  virtual void restore(const BlockMatrix& A, const SolverState& s);

 protected:
  explicit LinearSolver(SolverOptions o) : opt_(o) {}
  SolverOptions opt_;
};

/// The backend `automatic` starts with for a model of this many nodes (measured, docs/solvers.md).
[[nodiscard]] Backend default_backend(std::size_t nodes);

/// The number of MPI ranks the petsc backend shares its solves among: the size of
/// MPI_COMM_WORLD (MPI is started if the program did not), 1 in a build without hypre or PETSc.
/// Costs ~0.5 s the first time MPI starts, O(1) after.
[[nodiscard]] int solver_ranks();

/// A solver of backend b (automatic: see the backend list above; nodes is not used). Throws InputError if b is not
/// built in. O(1); the first solve allocates.
[[nodiscard]] std::unique_ptr<LinearSolver> make_solver(Backend b, SolverOptions options = {}, std::size_t nodes = 0);

}  // namespace sewn::physics::solve
