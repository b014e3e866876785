#pragma once
// Internal: the backends' constructors and what they share (not installed).

#include <chrono>
#include <cmath>
#include <memory>
#include <span>

#include "sewn/physics/solve/linear_solver.hpp"

namespace sewn::physics::solve::detail {

std::unique_ptr<LinearSolver> make_jacobi(SolverOptions o);
/// Backend::automatic: jacobi, switching to cholmod-pcg on a stiff small model (auto_solver.cpp).
std::unique_ptr<LinearSolver> make_auto(SolverOptions o);
std::unique_ptr<LinearSolver> make_sa_pcg(SolverOptions o);
#ifdef SEWN_HAVE_CHOLMOD
std::unique_ptr<LinearSolver> make_cholmod(SolverOptions o);
std::unique_ptr<LinearSolver> make_cholmod_pcg(SolverOptions o);
#endif
#ifdef SEWN_HAVE_HYPRE
std::unique_ptr<LinearSolver> make_hypre_pcg(SolverOptions o);
#endif
#ifdef SEWN_HAVE_PETSC
std::unique_ptr<LinearSolver> make_petsc(SolverOptions o);
#endif

/// Throws InputError unless b, x and free_dof (and mass_scale, if given) hold 3·A.size() values.
void check_sizes(const char* who, const BlockMatrix& A, std::span<const double> b, std::span<const double> x,
                 std::span<const double> free_dof, std::span<const double> mass_scale);

/// Throws SolverError naming `who`, the node and the axis if a free axis has a negative diagonal
/// entry, which proves A indefinite (CG or a preconditioner alone may not notice: CG can converge
/// on an indefinite matrix). Zero is let through: a node nothing stiffens or weighs has a zero row
/// and a zero right-hand side. O(n).
void check_diagonal(const char* who, const BlockMatrix& A, std::span<const double> free_dof);

/// The iterative stopping floor: absolute_tolerance · ‖S m‖ (0 without masses).
double absolute_floor(const SolverOptions& o, std::span<const double> free_dof, std::span<const double> mass_scale);

using Clock = std::chrono::steady_clock;
inline double ms_since(Clock::time_point t0) {
  return std::chrono::duration<double, std::milli>(Clock::now() - t0).count();
}

}  // namespace sewn::physics::solve::detail
