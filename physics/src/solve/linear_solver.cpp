#include "sewn/physics/solve/linear_solver.hpp"

#include <algorithm>
#include <array>
#include <string>

#include "../parallel/ranges.hpp"
#include "backends.hpp"
#include "mpi_module.hpp"
#include "sewn/physics/errors.hpp"

namespace sewn::physics::solve {

std::string_view to_string(Backend b) {
  switch (b) {
    case Backend::automatic: return "auto";
    case Backend::jacobi: return "jacobi";
    case Backend::cholmod: return "cholmod";
    case Backend::cholmod_pcg: return "cholmod-pcg";
    case Backend::hypre_pcg: return "hypre-pcg";
    case Backend::petsc: return "petsc";
    case Backend::sa_pcg: return "sa-pcg";
  }
  return "?";
}

namespace {
constexpr Backend all_backends[] = {Backend::jacobi, Backend::cholmod, Backend::cholmod_pcg, Backend::hypre_pcg,
                                   Backend::petsc, Backend::sa_pcg};

// The library a backend needs at build time, for the message when it is missing.
const char* library_of(Backend b) {
  switch (b) {
    case Backend::cholmod:
    case Backend::cholmod_pcg: return "SuiteSparse CHOLMOD (Debian libsuitesparse-dev)";
    case Backend::hypre_pcg: return "hypre (Debian libhypre-dev)";
    case Backend::petsc: return "PETSc (Debian libpetsc-real-dev)";
    default: return "nothing";
  }
}
}  // namespace

bool available(Backend b) {
  switch (b) {
    case Backend::automatic:
    case Backend::jacobi:
    case Backend::sa_pcg: return true;
    case Backend::cholmod:
    case Backend::cholmod_pcg:
#ifdef SEWN_HAVE_CHOLMOD
      return true;
#else
      return false;
#endif
    case Backend::hypre_pcg:
#ifdef SEWN_HAVE_HYPRE
      return true;
#else
      return false;
#endif
    case Backend::petsc:
#ifdef SEWN_HAVE_PETSC
      return true;
#else
      return false;
#endif
  }
  return false;
}

std::vector<Backend> available_backends() {
  std::vector<Backend> out;
  for (Backend b : all_backends)
    if (available(b)) out.push_back(b);
  return out;
}

namespace {
std::string built_in_list() {
  std::string s;
  for (Backend b : available_backends()) s += (s.empty() ? "" : ", ") + std::string(to_string(b));
  return s;
}
}  // namespace

Backend parse_backend(std::string_view name) {
  if (name == to_string(Backend::automatic)) return Backend::automatic;
  std::string all;
  for (Backend b : all_backends) {
    all += ", " + std::string(to_string(b));
    if (name != to_string(b)) continue;
    if (!available(b))
      throw InputError("solver '" + std::string(name) + "' is not built in (" + library_of(b) +
                       " was not found at build time); built in: auto, " + built_in_list());
    return b;
  }
  throw InputError("unknown solver '" + std::string(name) + "'; expected one of auto" + all + " (built in: auto, " +
                   built_in_list() + ")");
}

Backend default_backend(std::size_t nodes) {
  (void)nodes;
  // Measured (docs/solvers.md: bench/solve and profiles, CPU time per implicit step at equal or
  // better error): which backend wins is decided by stiffness against mass (block-Jacobi's
  // iteration count), not by the node count: cholmod-pcg (single-precision solves) wins on the
  // N = 8 cantilever at h = 10 ms (6561 nodes, ~590 iterations a step, ~1.6x) and loses on
  // the 8x8x10 beam (891 nodes) and on 16^3 at h = 0.1 ms (4913 nodes, 51 iterations, 5.6x
  // slower). So `auto` starts with jacobi at every size and switches on the iteration count
  // (auto_solver.cpp).
  return Backend::jacobi;
}

std::unique_ptr<LinearSolver> make_solver(Backend b, SolverOptions options, std::size_t nodes) {
  if (!(options.tolerance > 0 && options.tolerance < 1))
    throw InputError("solver tolerance must be in (0, 1), got " + std::to_string(options.tolerance));
  if (!(options.absolute_tolerance >= 0 && std::isfinite(options.absolute_tolerance)))
    throw InputError("solver absolute_tolerance must be finite and >= 0, got " + std::to_string(options.absolute_tolerance));
  if (options.max_iterations < 1)
    throw InputError("solver max_iterations must be >= 1, got " + std::to_string(options.max_iterations));
  (void)nodes;  // auto decides from the matrices it solves
  if (b == Backend::automatic) return detail::make_auto(options);
  (void)parse_backend(to_string(b));  // throws if not built in
  switch (b) {
#ifdef SEWN_HAVE_CHOLMOD
    case Backend::cholmod: return detail::make_cholmod(options);
    case Backend::cholmod_pcg: return detail::make_cholmod_pcg(options);
#endif
#ifdef SEWN_HAVE_HYPRE
    case Backend::hypre_pcg: return detail::mpi_backends().make_hypre_pcg(options);
#endif
#ifdef SEWN_HAVE_PETSC
    case Backend::petsc: return detail::mpi_backends().make_petsc(options);
#endif
    case Backend::sa_pcg: return detail::make_sa_pcg(options);
    default: return detail::make_jacobi(options);
  }
}

int solver_ranks() {
#ifdef SEWN_HAVE_MPI
  return detail::mpi_backends().ranks();
#else
  return 1;
#endif
}

void LinearSolver::restore(const BlockMatrix& /*A*/, const SolverState& s) {
  if (!s.factored.empty())
    throw InputError("LinearSolver::restore: the " + std::string(to_string(backend())) + " backend keeps no factorization, and the state holds " +
                     std::to_string(s.factored.size()) + " factored values");
}

namespace detail {

void check_sizes(const char* who, const BlockMatrix& A, std::span<const double> b, std::span<const double> x,
                 std::span<const double> free_dof, std::span<const double> mass_scale) {
  const std::size_t n3 = 3 * std::size_t{A.size()};
  if (b.size() != n3 || x.size() != n3 || free_dof.size() != n3 || (!mass_scale.empty() && mass_scale.size() != n3))
    throw InputError(std::string(who) + ": sizes do not match the matrix of " + std::to_string(A.size()) +
                     " nodes (expected " + std::to_string(n3) + " values; b " + std::to_string(b.size()) + ", x " +
                     std::to_string(x.size()) + ", free_dof " + std::to_string(free_dof.size()) + ", mass_scale " +
                     std::to_string(mass_scale.size()) + ")");
}

void check_diagonal(const char* who, const BlockMatrix& A, std::span<const double> free_dof) {
  // Split over nodes (a serial pass over 32³'s diagonal cost a 2-thread step ~1 %); each range
  // keeps its first bad entry and the first range's is named, as a serial pass would.
  const auto n = static_cast<std::size_t>(A.size());
  const int parts = physics::detail::parts_for(n, 1024);
  std::array<std::size_t, max_threads> first_bad;
  first_bad.fill(3 * n);
  physics::detail::run_parts(parts, [&](int t) {
    const std::size_t i1 = physics::detail::range_begin(n, parts, t + 1);
    for (std::size_t i = physics::detail::range_begin(n, parts, t); i < i1 && first_bad[static_cast<std::size_t>(t)] == 3 * n; ++i) {
      const double* B = A.block(A.diagonal(static_cast<Index>(i))).data();
      for (std::size_t a = 0; a < 3; ++a)
        if (free_dof[3 * i + a] != 0.0 && B[4 * a] < 0.0) {
          first_bad[static_cast<std::size_t>(t)] = 3 * i + a;
          break;
        }
    }
  });
  const std::size_t k = *std::min_element(first_bad.begin(), first_bad.begin() + parts);
  if (k == 3 * n) return;
  const double entry = A.block(A.diagonal(static_cast<Index>(k / 3)))(static_cast<Index>(k % 3), static_cast<Index>(k % 3));
  throw SolverError(std::string(who) + ": the matrix is not positive definite on the free axes (diagonal entry " +
                        std::to_string(entry) + " < 0 at node " + std::to_string(k / 3) + ", axis " + "xyz"[k % 3] + ")",
                    0, 0);
}

double absolute_floor(const SolverOptions& o, std::span<const double> free_dof, std::span<const double> mass_scale) {
  if (mass_scale.empty() || o.absolute_tolerance == 0.0) return 0.0;
  double s = 0;
  for (std::size_t k = 0; k < mass_scale.size(); ++k) s += free_dof[k] * mass_scale[k] * mass_scale[k];
  return o.absolute_tolerance * std::sqrt(s);
}

}  // namespace detail
}  // namespace sewn::physics::solve
