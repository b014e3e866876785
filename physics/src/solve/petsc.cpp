// The petsc backend: PETSc's KSP (CG with the GAMG algebraic multigrid preconditioner, or
// whatever PETSC_OPTIONS names, e.g. "-pc_type hypre") on every MPI rank of the program. Each
// rank holds the whole matrix (assembly is not distributed yet, docs/scaling.md) and gives
// PETSc the rows of its contiguous range of nodes; the solution is gathered back to every
// rank, so that every rank steps the same state. A collective call: every rank must solve.
// PETSc solves the filtered system K y = S(b - A x̃), K = S A S + (I - S), as the other
// backends do, from y = S x; the preconditioner is set up afresh at every solve, so a solve
// depends on its matrix alone (nothing to keep for a checkpoint).

#include <mpi.h>
#include <petscksp.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <string>
#include <vector>

#include "backends.hpp"
#include "mpi_session.hpp"
#include "sewn/physics/aligned.hpp"
#include "sewn/physics/errors.hpp"

namespace sewn::physics::solve::detail {

namespace {

bool petsc_finalized = false;

void ok(PetscErrorCode e, const char* what) {
  if (e != 0) throw SolverError(std::string("petsc solve: ") + what + " failed (PETSc error " + std::to_string(e) + ")", 0, 0);
}

// MPI, then PETSc, once per process; PETSc is finalised at exit before MPI. PETSc's signal
// handler stays off (a crash must reach the sanitizers and the test runner as it is), and
// its errors come back as codes, which become SolverErrors, instead of being printed.
void ensure_petsc() {
  static const bool started = [] {
    ensure_mpi();
    PetscBool up = PETSC_FALSE;
    PetscInitialized(&up);
    if (!up) {
      const LeakCheckPause pause;
      ok(PetscOptionsSetValue(nullptr, "-no_signal_handler", nullptr), "setting PETSc's options");
      ok(PetscInitializeNoArguments(), "PetscInitialize");
      std::atexit([] {
        petsc_finalized = true;
        const LeakCheckPause pause;
        PetscFinalize();
      });
    }
    PetscPushErrorHandler(PetscReturnErrorHandler, nullptr);
    return true;
  }();
  (void)started;
}

class PetscKsp final : public LinearSolver {
 public:
  explicit PetscKsp(SolverOptions o) : LinearSolver(o) {}
  ~PetscKsp() override { destroy(); }
  PetscKsp(const PetscKsp&) = delete;
  PetscKsp& operator=(const PetscKsp&) = delete;
  [[nodiscard]] Backend backend() const override { return Backend::petsc; }
  void reset() override { destroy(); }

  SolveReport solve(const BlockMatrix& A, std::span<const double> b, std::span<double> x, std::span<const double> free_dof,
                    std::span<const double> mass_scale) override {
    check_sizes("petsc solve", A, b, x, free_dof, mass_scale);
    check_diagonal("petsc solve", A, free_dof);
    SolveReport rep;
    rep.backend = Backend::petsc;
    auto t = Clock::now();
    if (!K_ || pattern_ != A.pattern_version()) {
      create(A);
      rep.symbolic_analyses = 1;
      rep.analyse_ms = ms_since(t);
      t = Clock::now();
    }
    fill(A, free_dof);
    // r = S(b - A x̃): every rank computes it whole (A, b and x are replicated).
    const std::size_t n3 = b.size();
    xt_.assign(n3, 0.0);
    for (std::size_t k = 0; k < n3; ++k) xt_[k] = free_dof[k] == 0.0 ? x[k] : 0.0;
    r_.resize(n3);
    A.multiply(xt_, r_);
    double bb = 0, rr = 0;
    for (std::size_t k = 0; k < n3; ++k) {
      r_[k] = free_dof[k] * (b[k] - r_[k]);
      bb += free_dof[k] * b[k] * b[k];
      rr += r_[k] * r_[k];
    }
    // PETSc stops at ‖r - K y‖ ≤ max(rtol ‖r‖, abstol); ‖r - K y‖ is ‖S(b - A x)‖, so rtol is
    // rescaled for the layer's rule ‖S(b - Ax)‖ ≤ max(tolerance ‖Sb‖, floor).
    const double floor = absolute_floor(opt_, free_dof, mass_scale);
    const double rtol = rr > 0 ? std::min(0.999, opt_.tolerance * std::sqrt(bb) / std::sqrt(rr)) : opt_.tolerance;
    ok(KSPSetTolerances(ksp_, rtol, floor, PETSC_DEFAULT, opt_.max_iterations), "setting the tolerances");
    set_local(b_, r_, free_dof, false);
    set_local(y_, x, free_dof, true);
    ok(KSPSetUp(ksp_), "the preconditioner's set-up");
    ++rep.factorizations;
    rep.factor_ms = ms_since(t);
    t = Clock::now();
    ok(KSPSolve(ksp_, b_, y_), "KSPSolve");
    KSPConvergedReason reason{};
    PetscInt its = 0;
    ok(KSPGetConvergedReason(ksp_, &reason), "reading the outcome");
    ok(KSPGetIterationNumber(ksp_, &its), "reading the outcome");
    if (reason == KSP_DIVERGED_INDEFINITE_MAT || reason == KSP_DIVERGED_INDEFINITE_PC || reason == KSP_DIVERGED_BREAKDOWN)
      throw SolverError("petsc solve: CG broke down (PETSc reason " + std::to_string(static_cast<int>(reason)) +
                            "): the matrix is not positive definite on the free axes",
                        static_cast<int>(its), 0.0);
    gather_into(x, free_dof);
    rep.iterations = static_cast<int>(its);
    // The layer's own residual, on the gathered x (the same on every rank).
    A.multiply(x, xt_);
    double res = 0;
    for (std::size_t k = 0; k < n3; ++k) {
      const double e = free_dof[k] * (b[k] - xt_[k]);
      res += e * e;
    }
    rep.residual = std::sqrt(res);
    rep.relative_residual = bb > 0 ? rep.residual / std::sqrt(bb) : 0.0;
    rep.converged = std::isfinite(rep.residual) && (rep.residual <= opt_.tolerance * std::sqrt(bb) * (1 + 1e-9) ||
                                                     rep.residual <= floor * (1 + 1e-9) || reason > 0);
    rep.solve_ms = ms_since(t);
    return rep;
  }

 private:
  // The matrix for A's pattern, split by nodes over the ranks, its vectors and the KSP.
  void create(const BlockMatrix& A) {
    ensure_petsc();
    destroy();
    int rank = 0, size = 1;
    MPI_Comm_rank(PETSC_COMM_WORLD, &rank);
    MPI_Comm_size(PETSC_COMM_WORLD, &size);
    const Index nb = A.size();
    first_ = static_cast<Index>(std::size_t{nb} * static_cast<std::size_t>(rank) / static_cast<std::size_t>(size));
    last_ = static_cast<Index>(std::size_t{nb} * static_cast<std::size_t>(rank + 1) / static_cast<std::size_t>(size));
    const auto local = static_cast<PetscInt>(3 * (last_ - first_));
    const auto global = static_cast<PetscInt>(3 * nb);
    const auto rows = A.row_offsets();
    std::vector<PetscInt> d_nnz, o_nnz;
    for (Index bi = first_; bi < last_; ++bi) {
      PetscInt d = 0, o = 0;
      for (Index k = rows[bi]; k < rows[bi + 1]; ++k) (A.columns()[k] >= first_ && A.columns()[k] < last_ ? d : o) += 3;
      for (int a = 0; a < 3; ++a) {
        d_nnz.push_back(d);
        o_nnz.push_back(o);
      }
    }
    ok(MatCreate(PETSC_COMM_WORLD, &K_), "creating the matrix");
    ok(MatSetSizes(K_, local, local, global, global), "sizing the matrix");
    ok(MatSetType(K_, MATAIJ), "creating the matrix");
    ok(MatSetBlockSize(K_, 3), "setting the block size");  // GAMG aggregates the 3 axes of a node together
    ok(MatSeqAIJSetPreallocation(K_, 0, d_nnz.data()), "preallocating the matrix");
    ok(MatMPIAIJSetPreallocation(K_, 0, d_nnz.data(), 0, o_nnz.data()), "preallocating the matrix");
    ok(MatSetOption(K_, MAT_NEW_NONZERO_ALLOCATION_ERR, PETSC_TRUE), "setting the matrix options");
    ok(MatCreateVecs(K_, &y_, &b_), "creating the vectors");
    ok(VecScatterCreateToAll(y_, &gather_, &all_), "creating the gather");
    ok(KSPCreate(PETSC_COMM_WORLD, &ksp_), "creating the KSP");
    ok(KSPSetType(ksp_, KSPCG), "choosing CG");
    PC pc = nullptr;
    ok(KSPGetPC(ksp_, &pc), "choosing the preconditioner");
    ok(PCSetType(pc, PCGAMG), "choosing GAMG");
    ok(KSPSetNormType(ksp_, KSP_NORM_UNPRECONDITIONED), "choosing the residual norm");
    ok(KSPSetInitialGuessNonzero(ksp_, PETSC_TRUE), "keeping the warm start");
    ok(KSPSetFromOptions(ksp_), "reading PETSC_OPTIONS");
    pattern_ = A.pattern_version();
  }

  // K's values on this rank's rows; a zero diagonal becomes 1, as in the other backends.
  void fill(const BlockMatrix& A, std::span<const double> free_dof) {
    const auto rows = A.row_offsets();
    std::vector<PetscInt> cols;
    std::vector<PetscScalar> vals;
    for (Index bi = first_; bi < last_; ++bi)
      for (int a = 0; a < 3; ++a) {
        const std::size_t row = 3 * std::size_t{bi} + static_cast<std::size_t>(a);
        cols.clear();
        vals.clear();
        for (Index k = rows[bi]; k < rows[bi + 1]; ++k) {
          const Index bj = A.columns()[k];
          const auto blk = A.block(k);
          for (int c = 0; c < 3; ++c) {
            const std::size_t col = 3 * std::size_t{bj} + static_cast<std::size_t>(c);
            double v = free_dof[row] * free_dof[col] * blk(a, c);
            if (col == row && v == 0.0) v = 1.0;
            cols.push_back(static_cast<PetscInt>(col));
            vals.push_back(v);
          }
        }
        const auto r = static_cast<PetscInt>(row);
        ok(MatSetValues(K_, 1, &r, static_cast<PetscInt>(cols.size()), cols.data(), vals.data(), INSERT_VALUES),
           "setting the matrix values");
      }
    ok(MatAssemblyBegin(K_, MAT_FINAL_ASSEMBLY), "assembling the matrix");
    ok(MatAssemblyEnd(K_, MAT_FINAL_ASSEMBLY), "assembling the matrix");
    ok(KSPSetOperators(ksp_, K_, K_), "setting the operator");
  }

  // v's local part from this rank's rows of `from` (times the mask if `masked`).
  void set_local(Vec v, std::span<const double> from, std::span<const double> free_dof, bool masked) {
    PetscScalar* a = nullptr;
    ok(VecGetArray(v, &a), "writing a vector");
    const std::size_t lo = 3 * std::size_t{first_}, hi = 3 * std::size_t{last_};
    for (std::size_t k = lo; k < hi; ++k) a[k - lo] = masked ? free_dof[k] * from[k] : from[k];
    ok(VecRestoreArray(v, &a), "writing a vector");
  }

  // y gathered on every rank into x's free axes.
  void gather_into(std::span<double> x, std::span<const double> free_dof) {
    ok(VecScatterBegin(gather_, y_, all_, INSERT_VALUES, SCATTER_FORWARD), "gathering the solution");
    ok(VecScatterEnd(gather_, y_, all_, INSERT_VALUES, SCATTER_FORWARD), "gathering the solution");
    const PetscScalar* a = nullptr;
    ok(VecGetArrayRead(all_, &a), "reading the solution");
    for (std::size_t k = 0; k < x.size(); ++k)
      if (free_dof[k] != 0.0) x[k] = a[k];
    ok(VecRestoreArrayRead(all_, &a), "reading the solution");
  }

  void destroy() {
    if (!petsc_finalized) {
      if (ksp_) KSPDestroy(&ksp_);
      if (K_) MatDestroy(&K_);
      if (y_) VecDestroy(&y_);
      if (b_) VecDestroy(&b_);
      if (all_) VecDestroy(&all_);
      if (gather_) VecScatterDestroy(&gather_);
    }
    ksp_ = nullptr;
    K_ = nullptr;
    y_ = b_ = all_ = nullptr;
    gather_ = nullptr;
  }

  KSP ksp_ = nullptr;
  Mat K_ = nullptr;
  Vec y_ = nullptr, b_ = nullptr, all_ = nullptr;
  VecScatter gather_ = nullptr;
  std::uint64_t pattern_ = 0;
  Index first_ = 0, last_ = 0;
  AlignedVector<double> xt_, r_;
};

}  // namespace

std::unique_ptr<LinearSolver> make_petsc(SolverOptions o) { return std::make_unique<PetscKsp>(o); }

}  // namespace sewn::physics::solve::detail
