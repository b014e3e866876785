// The reference backend: block-Jacobi PCG (physics/src/cg.cpp) behind the solver interface.

#include "backends.hpp"
#include "sewn/physics/aligned.hpp"
#include "sewn/physics/cg.hpp"
#include "sewn/physics/errors.hpp"

#include <string>

namespace sewn::physics::solve::detail {

namespace {

class JacobiPcg final : public LinearSolver {
 public:
  explicit JacobiPcg(SolverOptions o) : LinearSolver(o) {}
  [[nodiscard]] Backend backend() const override { return Backend::jacobi; }

  SolveReport solve(const BlockMatrix& A, std::span<const double> b, std::span<double> x, std::span<const double> free_dof,
                    std::span<const double> mass_scale) override {
    check_sizes("jacobi solve", A, b, x, free_dof, mass_scale);
    const auto t0 = Clock::now();
    check_diagonal("jacobi solve", A, free_dof);
    precond_.resize(9 * std::size_t{A.size()});
    block_jacobi_inverse(A, free_dof, precond_);
    const CgResult cg = filtered_pcg(A, b, x, free_dof, precond_, opt_.tolerance, opt_.max_iterations, ws_,
                                     absolute_floor(opt_, free_dof, mass_scale));
    SolveReport r;
    r.backend = Backend::jacobi;
    r.iterations = cg.iterations;
    r.relative_residual = cg.relative_residual;
    double b2 = 0;
    for (std::size_t k = 0; k < b.size(); ++k) b2 += free_dof[k] * b[k] * b[k];
    r.residual = cg.relative_residual * std::sqrt(b2);
    r.converged = cg.converged;
    r.solve_ms = ms_since(t0);
    if (cg.breakdown) throw_breakdown(cg);
    return r;
  }

 private:
  [[noreturn]] static void throw_breakdown(const CgResult& cg);
  AlignedVector<double> precond_;
  CgWorkspace ws_;
};

void JacobiPcg::throw_breakdown(const CgResult& cg) {
  throw SolverError("jacobi solve: CG broke down after " + std::to_string(cg.iterations) +
                        " iterations (pᵀAp ≤ 0): the matrix is not positive definite on the free axes",
                    cg.iterations, cg.relative_residual);
}

}  // namespace

std::unique_ptr<LinearSolver> make_jacobi(SolverOptions o) { return std::make_unique<JacobiPcg>(o); }

}  // namespace sewn::physics::solve::detail
