// The hypre-pcg backend: CG preconditioned by one V-cycle of hypre's BoomerAMG (algebraic
// multigrid) set up on a recent matrix and kept across solves (KeptPcg, kept_pcg.hpp). The
// hierarchy is built on the filtered matrix K = S A S + (I - S), as CHOLMOD's factor is; the
// three axes of a node are told to BoomerAMG as three functions (systems AMG, unknown
// approach), which coarsens each displacement component on its own couplings.

#include <HYPRE.h>
#include <HYPRE_parcsr_ls.h>
#include <HYPRE_utilities.h>
#include <mpi.h>

#include <algorithm>
#include <cstdlib>
#include <numeric>
#include <string>
#include <vector>

#include "backends.hpp"
#include "kept_pcg.hpp"
#include "mpi_session.hpp"
#include "sewn/physics/errors.hpp"

namespace sewn::physics::solve::detail {

namespace {

bool hypre_finalized = false;

constexpr double amg_setup_iterations = 10;  // see AmgHierarchy::setup_cost()

// MPI, then hypre's own state, once per process; hypre is finalised at exit before MPI
// (atexit runs in reverse order of registration).
void ensure_hypre() {
  static const bool started = [] {
    ensure_mpi();
    {
      const LeakCheckPause pause;
      HYPRE_Init();
    }
    std::atexit([] {
      hypre_finalized = true;
      const LeakCheckPause pause;
      HYPRE_Finalize();
    });
    return true;
  }();
  (void)started;
}

void check(HYPRE_Int status, const char* what) {
  if (status != 0) {
    HYPRE_ClearAllErrors();
    throw SolverError(std::string("hypre-pcg: ") + what + " failed (hypre error " + std::to_string(status) + ")", 0, 0);
  }
}

// The filtered matrix in CSR (both triangles, rows 3i+a in order) and its BoomerAMG hierarchy.
class AmgHierarchy {
 public:
  AmgHierarchy() = default;
  ~AmgHierarchy() { free_hierarchy(); }
  AmgHierarchy(const AmgHierarchy&) = delete;
  AmgHierarchy& operator=(const AmgHierarchy&) = delete;

  /// Rebuilds K's CSR pattern if A's changed; true then. O(blocks).
  bool sync_pattern(const BlockMatrix& A) {
    if (have_pattern_ && pattern_ == A.pattern_version()) return false;
    free_hierarchy();
    const Index nb = A.size();
    const std::size_t n = 3 * std::size_t{nb};
    const auto rows = A.row_offsets();
    row_size_.assign(n, 0);
    col_.clear();
    src_.clear();
    diag_.assign(n, 0);
    col_.reserve(9 * std::size_t{A.num_blocks()});
    src_.reserve(col_.capacity());
    // Row 3bi+a holds columns 3bj+c of the blocks (bi, bj) of block row bi; A(bi,bj)(a,c) sits
    // in that block's column-major storage at 3c + a.
    for (Index bi = 0; bi < nb; ++bi)
      for (int a = 0; a < 3; ++a) {
        const std::size_t row = 3 * std::size_t{bi} + static_cast<std::size_t>(a);
        for (Index k = rows[bi]; k < rows[bi + 1]; ++k) {
          const Index bj = A.columns()[k];
          for (int c = 0; c < 3; ++c) {
            const std::size_t column = 3 * std::size_t{bj} + static_cast<std::size_t>(c);
            if (column == row) diag_[row] = col_.size();
            col_.push_back(static_cast<HYPRE_BigInt>(column));
            src_.push_back(9 * std::size_t{k} + 3 * static_cast<std::size_t>(c) + static_cast<std::size_t>(a));
          }
        }
        row_size_[row] = static_cast<HYPRE_Int>(3 * (rows[bi + 1] - rows[bi]));
      }
    row_index_.resize(n);
    std::iota(row_index_.begin(), row_index_.end(), HYPRE_BigInt{0});
    values_.assign(col_.size(), 0.0);
    pattern_ = A.pattern_version();
    have_pattern_ = true;
    analysed_ = false;
    return true;
  }

  [[nodiscard]] bool analysed() const { return analysed_; }
  /// Starts MPI and hypre if needed; the pattern itself was built by sync_pattern().
  void analyse() {
    ensure_hypre();
    analysed_ = true;
  }

  /// K's values from A and the mask; a zero diagonal (fixed axis, or a node nothing weighs or
  /// stiffens) becomes 1, as in the CHOLMOD backends. O(entries).
  void fill_values(const BlockMatrix& A, std::span<const double> free_dof) {
    const double* val = A.num_blocks() ? A.block(0).data() : nullptr;
    std::size_t e = 0;
    for (std::size_t row = 0; row < row_size_.size(); ++row)
      for (HYPRE_Int m = 0; m < row_size_[row]; ++m, ++e) {
        const auto column = static_cast<std::size_t>(col_[e]);
        values_[e] = free_dof[row] * free_dof[column] * val[src_[e]];
      }
    for (std::size_t row = 0; row < diag_.size(); ++row)
      if (values_[diag_[row]] == 0.0) values_[diag_[row]] = 1.0;
  }

  /// BoomerAMG's set-up on K's current values. Throws SolverError naming the node and axis of a
  /// negative diagonal entry (which proves K indefinite; AMG itself would not notice).
  void factorize(const char* who, bool keep_values) {
    valid_ = false;
    for (std::size_t row = 0; row < diag_.size(); ++row)
      if (values_[diag_[row]] < 0.0)
        throw SolverError(std::string(who) + ": the matrix is not positive definite on the free axes (diagonal entry " +
                              std::to_string(values_[diag_[row]]) + " < 0 at node " + std::to_string(row / 3) + ", axis " +
                              "xyz"[row % 3] + ")",
                          0, 0);
    free_hierarchy();
    const auto n = static_cast<HYPRE_BigInt>(row_size_.size());
    check(HYPRE_IJMatrixCreate(MPI_COMM_SELF, 0, n - 1, 0, n - 1, &ij_), "creating the matrix");
    check(HYPRE_IJMatrixSetObjectType(ij_, HYPRE_PARCSR), "creating the matrix");
    check(HYPRE_IJMatrixSetRowSizes(ij_, row_size_.data()), "sizing the matrix");
    check(HYPRE_IJMatrixInitialize(ij_), "initialising the matrix");
    check(HYPRE_IJMatrixSetValues(ij_, static_cast<HYPRE_Int>(n), row_size_.data(), row_index_.data(), col_.data(),
                                  values_.data()),
          "setting the matrix values");
    check(HYPRE_IJMatrixAssemble(ij_), "assembling the matrix");
    check(HYPRE_IJMatrixGetObject(ij_, reinterpret_cast<void**>(&parcsr_)), "assembling the matrix");
    for (auto* v : {&ij_b_, &ij_x_}) {
      check(HYPRE_IJVectorCreate(MPI_COMM_SELF, 0, n - 1, v), "creating a vector");
      check(HYPRE_IJVectorSetObjectType(*v, HYPRE_PARCSR), "creating a vector");
      check(HYPRE_IJVectorInitialize(*v), "creating a vector");
      check(HYPRE_IJVectorAssemble(*v), "creating a vector");
    }
    check(HYPRE_IJVectorGetObject(ij_b_, reinterpret_cast<void**>(&par_b_)), "creating a vector");
    check(HYPRE_IJVectorGetObject(ij_x_, reinterpret_cast<void**>(&par_x_)), "creating a vector");
    check(HYPRE_BoomerAMGCreate(&amg_), "creating BoomerAMG");
    // One V-cycle per application, as a preconditioner: no tolerance, no printing. Symmetric
    // smoothing (hybrid symmetric Gauss-Seidel) keeps the preconditioner symmetric, as CG needs;
    // HMIS coarsening with extended+i interpolation and a strength threshold of 0.5 are hypre's
    // advice for 3D problems.
    HYPRE_BoomerAMGSetPrintLevel(amg_, 0);
    HYPRE_BoomerAMGSetMaxIter(amg_, 1);
    HYPRE_BoomerAMGSetTol(amg_, 0.0);
    HYPRE_BoomerAMGSetRelaxType(amg_, 6);
    HYPRE_BoomerAMGSetNumSweeps(amg_, 1);
    HYPRE_BoomerAMGSetCoarsenType(amg_, 10);
    HYPRE_BoomerAMGSetInterpType(amg_, 6);
    HYPRE_BoomerAMGSetPMaxElmts(amg_, 4);
    HYPRE_BoomerAMGSetStrongThreshold(amg_, 0.5);
    HYPRE_BoomerAMGSetNumFunctions(amg_, 3);
    check(HYPRE_BoomerAMGSetup(amg_, parcsr_, par_b_, par_x_), "BoomerAMG set-up");
    if (keep_values) factored_ = values_;
    valid_ = true;
  }

  [[nodiscard]] bool valid() const { return valid_; }
  [[nodiscard]] const std::vector<double>& factored_values() const { return factored_; }
  /// A set-up's cost in PCG iterations (KeptPcg's refresh rule): BoomerAMG's set-up, measured
  /// against its V-cycle (with the product) in CPU time, cost 10.6 iterations on the
  /// 8x8x10 beam and 10.2 on the N = 8 cantilever (docs/solvers.md). A constant: the rule must not
  /// depend on timings.
  [[nodiscard]] double setup_cost() const { return amg_setup_iterations; }

  /// Sets up on `values` as K's on A's pattern (a kept hierarchy taken up again). Throws
  /// InputError if their count is not the pattern's.
  void factor_values(const BlockMatrix& A, std::span<const double> values, const char* who) {
    sync_pattern(A);
    if (values.size() != values_.size())
      throw InputError(std::string(who) + ": " + std::to_string(values.size()) + " factored values for a pattern of " +
                       std::to_string(values_.size()) + " entries");
    if (!analysed()) analyse();
    std::copy(values.begin(), values.end(), values_.begin());
    factorize(who, true);
  }

  void forget() {
    free_hierarchy();
    have_pattern_ = analysed_ = false;
  }

  /// z = one V-cycle applied to r, from a zero guess. O(entries of the hierarchy).
  void solve(std::span<const double> r, std::span<double> z) {
    const auto n = static_cast<HYPRE_Int>(r.size());
    check(HYPRE_IJVectorSetValues(ij_b_, n, row_index_.data(), r.data()), "setting a vector");
    std::fill(z.begin(), z.end(), 0.0);
    check(HYPRE_IJVectorSetValues(ij_x_, n, row_index_.data(), z.data()), "setting a vector");
    // A solve that stops on its iteration limit (1) reports it as hypre's convergence error;
    // that is what a preconditioner asks for, so it is cleared, not thrown.
    HYPRE_BoomerAMGSolve(amg_, parcsr_, par_b_, par_x_);
    HYPRE_ClearAllErrors();
    check(HYPRE_IJVectorGetValues(ij_x_, n, row_index_.data(), z.data()), "reading a vector");
  }

 private:
  void free_hierarchy() {
    valid_ = false;
    if (hypre_finalized) return;  // the process is exiting: hypre's memory went with it
    if (amg_) HYPRE_BoomerAMGDestroy(amg_);
    if (ij_) HYPRE_IJMatrixDestroy(ij_);
    if (ij_b_) HYPRE_IJVectorDestroy(ij_b_);
    if (ij_x_) HYPRE_IJVectorDestroy(ij_x_);
    amg_ = nullptr;
    ij_ = nullptr;
    ij_b_ = ij_x_ = nullptr;
  }

  HYPRE_Solver amg_ = nullptr;
  HYPRE_IJMatrix ij_ = nullptr;
  HYPRE_IJVector ij_b_ = nullptr, ij_x_ = nullptr;
  HYPRE_ParCSRMatrix parcsr_ = nullptr;
  HYPRE_ParVector par_b_ = nullptr, par_x_ = nullptr;
  std::uint64_t pattern_ = 0;
  bool have_pattern_ = false, analysed_ = false, valid_ = false;
  std::vector<HYPRE_Int> row_size_;
  std::vector<HYPRE_BigInt> row_index_, col_;
  std::vector<std::size_t> src_, diag_;  // per entry: its index in A's values; per row: its diagonal entry
  std::vector<double> values_, factored_;
};

}  // namespace

std::unique_ptr<LinearSolver> make_hypre_pcg(SolverOptions o) {
  return std::make_unique<KeptPcg<AmgHierarchy>>(o, Backend::hypre_pcg, "hypre-pcg");
}

}  // namespace sewn::physics::solve::detail
