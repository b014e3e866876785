#pragma once
// BlockCholesky: a sparse supernodal LLᵀ factorization on BlockMatrix's 3×3 blocks (the direct
// backend and cholmod-pcg's kept factor, cholmod.cpp, use it below block_factor_flops: every
// matrix measured).
//
// Why: every entry of the solver layer's matrices belongs to a 3×3 block (a node's axes, or
// three rod angles), so the symbolic work runs on the block graph, 9× smaller. A first version
// factored one 3×3 block column at a time (left-looking, fixed-size products): 4x faster than
// CHOLMOD's simplicial code on the toy ball, but on the frisbee (933 unknowns, 8e6 flops, the
// trailing columns nearly dense) it ran at 3.5-9 GFlop/s. Block columns whose structure below
// the diagonal nests (a chain in the elimination tree) are merged into supernodes: from
// dense_width pivots on, dense column-major panels factored with Eigen's dense kernels (LLᵀ,
// triangular solves, GEMM); narrower ones one pivot at a time as before (fixed-size 3×3 code),
// which is faster on sparse matrices. docs/solvers.md has the measurements.
//
// It factors the filtered matrix K = S A S + (I - S) of the solver layer (S the diagonal 0/1
// mask of free axes; a free axis with a zero diagonal gets 1 too, as CHOLMOD's backends do),
// in a fill-reducing order (AMD on the block graph, then a postorder of the elimination tree so
// that supernodes are contiguous), the analysis kept while A's pattern is.

#include <cstdint>
#include <span>
#include <vector>

#include "sewn/physics/aligned.hpp"
#include "sewn/physics/block_matrix.hpp"

namespace sewn::physics::solve {

class BlockCholesky {
 public:
  /// Symbolic analysis of A's pattern: the ordering, L's supernodes, the scatter of A's
  /// blocks. Kept until A's pattern_version() changes. O(blocks of L · log).
  void analyse(const BlockMatrix& A);
  /// True if analyse() ran on A's current pattern.
  [[nodiscard]] bool analysed_for(const BlockMatrix& A) const { return pattern_ != 0 && pattern_ == A.pattern_version(); }
  /// Flops of one numeric factorization (counted as a scalar LLᵀ's, 3×3 blocks dense).
  [[nodiscard]] double flops() const { return flops_; }
  /// Scalars of L (diagonal blocks' lower triangles and off-diagonal blocks).
  [[nodiscard]] double factor_entries() const { return entries_; }
  /// Scalars stored in the supernodal panels: factor_entries() plus the unused upper
  /// triangles of their diagonal blocks.
  [[nodiscard]] double stored_entries() const { return sn_val_.empty() ? 0.0 : static_cast<double>(sn_val_.back()); }
  /// Supernodes of the analysis (sets of consecutive pivots sharing one dense panel).
  [[nodiscard]] std::size_t supernodes() const { return sn_first_.empty() ? 0 : sn_first_.size() - 1; }

  /// Numeric factorization of K (the header) for A's values, analysed first if its pattern is
  /// new. Throws SolverError (naming `who`, the node and the axis) where a pivot is not
  /// positive: K is not positive definite on the free axes. O(flops()).
  void factorize(const BlockMatrix& A, std::span<const double> free_dof, const char* who);
  /// out = K⁻¹ rhs (3n values each; may alias) with the last factor. O(stored entries).
  void solve(std::span<const double> rhs, std::span<double> out);
  /// After each factorization, also round the panels to float and solve on them (arithmetic
  /// in double): for a factor kept as a preconditioner, whose solves are memory bound, half the
  /// bytes (cholmod-pcg; float_factor.hpp has the why). A factor whose values float cannot hold
  /// keeps the double solves. Off by default. O(1).
  void set_single_solves(bool on) { single_ = on; }
  /// True if solve() runs on the float panels. O(1).
  [[nodiscard]] bool single_solves() const { return !lf_.empty(); }

 private:
  void order(const BlockMatrix& A);
  void postorder(const BlockMatrix& A);
  void symbolic(const BlockMatrix& A);
  void partition(const std::vector<Index>& parent, const std::vector<std::size_t>& col, const std::vector<Index>& row);
  void scatter_supernode(const BlockMatrix& A, std::span<const double> free_dof, std::size_t s);
  void update_supernode(std::size_t s);
  void finish_supernode(std::size_t s, const char* who);
  void factor_pivot(const BlockMatrix& A, std::span<const double> free_dof, std::size_t s, const char* who);
  [[noreturn]] void not_positive_definite(std::size_t pivot, const char* who) const;
  [[nodiscard]] bool round_panels();
  template <class T>
  void solve_panels(const T* lx);
  [[nodiscard]] std::size_t width_of(std::size_t s) const { return sn_first_[s + 1] - sn_first_[s]; }
  [[nodiscard]] std::size_t below_of(std::size_t s) const { return sn_rows_[s + 1] - sn_rows_[s]; }

  std::uint64_t pattern_ = 0;
  std::vector<Index> perm_, pinv_;  // pivot j is node perm_[j]; node i is pivot pinv_[i]
  // Supernode s: pivots sn_first_[s] .. sn_first_[s+1), the block rows below them
  // rows_[sn_rows_[s] .. sn_rows_[s+1]) (ascending), its panel at lx_[sn_val_[s]]: column-major,
  // 3 (width + rows below) scalar rows by 3 width columns, the diagonal block on top; one pivot
  // wide, its 3×3 blocks one after another, the diagonal one L(j, j)⁻¹ (the solves multiply).
  std::vector<Index> sn_first_, rows_;
  std::vector<std::size_t> sn_of_;  // pivot -> its supernode
  std::vector<std::size_t> sn_rows_, sn_val_;
  // A's blocks scattered into the panels, by pivot column: slot in A, pivot row, offset in lx_
  // (in a one-pivot supernode unused: factor_pivot() scatters by pivot row)
  std::vector<std::size_t> a_col_, a_dst_;
  std::vector<Index> a_slot_, a_row_;
  // The panels, and one value past them: the solves read a one-pivot block's columns 4 values
  // at a time, the last one reaching one past the block.
  AlignedVector<double> lx_;
  AlignedVector<float> lf_;    // lx_ rounded to float (set_single_solves), else empty
  bool single_ = false;
  AlignedVector<double> w_;    // factor_pivot()'s column: 9 per pivot row, zero between pivots
  AlignedVector<double> tmp_;  // a descendant's update (factorize) or a panel's rows (solve)
  AlignedVector<double> y_;    // the permuted vector of solve(): 4 per pivot (the 4th a scratch lane)
  // Left-looking: supernode s is updated by the supernodes upd_from_[u] for u in
  // upd_start_[s] .. upd_start_[s+1), from their rows at rows_[upd_row_[u]] on (upd_rows_[u]
  // of them); from a one-pivot supernode, upd_block_[u] is the first of those blocks in lx_
  std::vector<std::size_t> upd_start_, upd_from_, upd_row_, upd_rows_, upd_block_;
  std::vector<std::size_t> relpos_;  // pivot row -> its block row within the current panel
  std::vector<std::size_t> pos_;     // the current descendant's rows' relpos_
  double flops_ = 0, entries_ = 0;
};

}  // namespace sewn::physics::solve
