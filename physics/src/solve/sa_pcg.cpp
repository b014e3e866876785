// The sa-pcg backend: CG preconditioned by one symmetric V-cycle of our own aggregation
// multigrid on rigid-body modes (aggregation.hpp), its coarse levels set up on a recent matrix and kept across
// solves by the refresh rule of cholmod-pcg and hypre-pcg (KeptPcg, kept_pcg.hpp). Block-Jacobi
// misses the low-frequency modes of a long stiff body (the bending of a cantilever); the coarse
// spaces built from the rigid-body modes of small aggregates of nodes carry exactly those.

#include <algorithm>
#include <string>
#include <vector>

#include "aggregation.hpp"
#include "backends.hpp"
#include "kept_pcg.hpp"
#include "sewn/physics/errors.hpp"

namespace sewn::physics::solve::detail {

namespace {

// A set-up's cost in CG iterations of sa-pcg (KeptPcg's refresh rule): measured in CPU time
// against its iterations once they ran on the packed product (docs/solvers.md), ~230 on the
// 8x8x10 beam (30 ms against 0.13 ms) and ~170 on the N = 8 cantilever (250 ms against 1.45 ms);
// it was 40 when an iteration cost 26 of block-Jacobi's. A constant, so that the rule does not
// depend on timings.
constexpr double sa_setup_iterations = 200;

class SaPreconditioner {
 public:
  /// Notes A's pattern; true (and the hierarchy forgotten) if it changed. O(nodes + blocks).
  bool sync_pattern(const BlockMatrix& A) {
    if (have_pattern_ && pattern_ == A.pattern_version()) return false;
    hierarchy_.clear();
    valid_ = false;
    rows_.assign(A.row_offsets().begin(), A.row_offsets().end());
    cols_.assign(A.columns().begin(), A.columns().end());
    pattern_ = A.pattern_version();
    have_pattern_ = true;
    analysed_ = false;
    return true;
  }
  // The per-pattern set-up is the pattern's copy above; analyse() only records that this
  // pattern has had it, so the solve report counts one analysis per pattern (as the other
  // kept preconditioners do) and a cut shows in it.
  [[nodiscard]] bool analysed() const { return have_pattern_ && analysed_; }
  void analyse() { analysed_ = true; }

  /// The set-up's input from A: its filtered blocks (S A S + I - S; a zero diagonal entry,
  /// a node nothing weighs or stiffens, becomes 1), the mask and the coordinates last given.
  /// Laid out as SolverState's values: blocks, then mask, then coordinates. O(blocks).
  void fill_values(const BlockMatrix& A, std::span<const double> free_dof) {
    const std::size_t nb = static_cast<std::size_t>(A.num_blocks()), n3 = free_dof.size();
    const bool with_xyz = coordinates_.size() == n3;
    input_.assign(9 * nb + n3 + (with_xyz ? n3 : 0), 0.0);
    const double* val = nb ? A.block(0).data() : nullptr;
    for (Index bi = 0; bi < A.size(); ++bi)
      for (Index k = rows_[bi]; k < rows_[bi + 1]; ++k) {
        const Index bj = cols_[k];
        for (int c = 0; c < 3; ++c)
          for (int a = 0; a < 3; ++a) {
            const std::size_t e = 9 * std::size_t(k) + 3 * std::size_t(c) + std::size_t(a);
            double v = free_dof[3 * std::size_t(bi) + std::size_t(a)] * free_dof[3 * std::size_t(bj) + std::size_t(c)] * val[e];
            if (bi == bj && a == c && v == 0.0) v = 1.0;
            input_[e] = v;
          }
      }
    std::copy(free_dof.begin(), free_dof.end(), input_.begin() + std::ptrdiff_t(9 * nb));
    if (with_xyz) std::copy(coordinates_.begin(), coordinates_.end(), input_.begin() + std::ptrdiff_t(9 * nb + n3));
  }

  /// Builds the hierarchy on the values of fill_values() (or factor_values()).
  void factorize(const char* who, bool /*keep_values: the input is the state*/) {
    valid_ = false;
    const std::size_t nb = cols_.size(), n3 = 3 * (rows_.size() - 1);
    FineInput in;
    in.rows = rows_;
    in.columns = cols_;
    in.values = std::span<const double>(input_).subspan(0, 9 * nb);
    in.free_dof = std::span<const double>(input_).subspan(9 * nb, n3);
    if (input_.size() == 9 * nb + 2 * n3) in.coordinates = std::span<const double>(input_).subspan(9 * nb + n3);
    check_diagonal_entries(who);
    hierarchy_.build(in, who);
    valid_ = true;
  }

  // A negative diagonal entry proves the matrix indefinite: named by node and axis (the
  // hierarchy's own check names a 3x3 block only).
  void check_diagonal_entries(const char* who) const {
    for (std::size_t bi = 0; bi + 1 < rows_.size(); ++bi)
      for (Index k = rows_[bi]; k < rows_[bi + 1]; ++k) {
        if (std::size_t(cols_[k]) != bi) continue;
        for (int a = 0; a < 3; ++a) {
          const double d = input_[9 * std::size_t(k) + 4 * std::size_t(a)];
          if (d < 0.0)
            throw SolverError(std::string(who) + ": the matrix is not positive definite on the free axes (diagonal entry " +
                                  std::to_string(d) + " < 0 at node " + std::to_string(bi) + ", axis " + "xyz"[a] + ")",
                              0, 0);
        }
      }
  }

  [[nodiscard]] double setup_cost() const { return sa_setup_iterations; }
  [[nodiscard]] bool valid() const { return valid_; }
  [[nodiscard]] const std::vector<double>& factored_values() const { return input_; }

  void factor_values(const BlockMatrix& A, std::span<const double> values, const char* who) {
    sync_pattern(A);
    const std::size_t nb = cols_.size(), n3 = 3 * std::size_t(A.size());
    if (values.size() != 9 * nb + n3 && values.size() != 9 * nb + 2 * n3)
      throw InputError(std::string(who) + ": " + std::to_string(values.size()) + " set-up values for a pattern of " +
                       std::to_string(nb) + " blocks and " + std::to_string(A.size()) + " nodes (expected " +
                       std::to_string(9 * nb + n3) + " or, with coordinates, " + std::to_string(9 * nb + 2 * n3) + ")");
    input_.assign(values.begin(), values.end());
    factorize(who, true);
  }

  void forget() {
    hierarchy_.clear();
    have_pattern_ = analysed_ = valid_ = false;
  }

  /// The nodes' positions for the rigid-body modes of the next set-up.
  void set_coordinates(std::span<const double> xyz) { coordinates_.assign(xyz.begin(), xyz.end()); }

  /// The current solve's matrix: the fine level of the V-cycle smooths with it, and the CG
  /// (KeptPcg's padded path) multiplies by it, both through the packed symmetric product.
  void bind(const BlockMatrix& A, std::span<const double> free_dof) { fine_.bind(A, free_dof); }
  [[nodiscard]] FineLevel& fine() { return fine_; }

  /// z = one V-cycle on r, padded vectors (FineLevel).
  void solve4(const double* r, double* z) { hierarchy_.vcycle(fine_, r, z); }

  [[nodiscard]] const SaHierarchy& hierarchy() const { return hierarchy_; }

 private:
  SaHierarchy hierarchy_;
  std::uint64_t pattern_ = 0;
  bool have_pattern_ = false, analysed_ = false, valid_ = false;
  std::vector<Index> rows_, cols_;
  std::vector<double> input_, coordinates_;
  FineLevel fine_;
};

}  // namespace

std::unique_ptr<LinearSolver> make_sa_pcg(SolverOptions o) {
  return std::make_unique<KeptPcg<SaPreconditioner>>(o, Backend::sa_pcg, "sa-pcg");
}

}  // namespace sewn::physics::solve::detail
