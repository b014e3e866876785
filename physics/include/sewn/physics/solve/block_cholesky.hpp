#pragma once
// BlockCholesky: a sparse LLᵀ factorization on BlockMatrix's 3×3 blocks, for the small
// systems where CHOLMOD's supernodal BLAS path does not pay (the direct backend, cholmod.cpp,
// uses it below block_factor_flops).
//
// Why: the toy ball's Newton matrix (1251 unknowns, 8.3e5 flops: a rod chain, a small tet
// mesh) factored by CHOLMOD's simplicial up-looking code took ~1 ms, 0.8 GFlop/s, plus a
// permuted transpose of K per call; on the sandwich's (594 unknowns, 2.9e6 flops) its
// supernodes are a few columns wide, too narrow for BLAS calls to pay. Every entry of such a
// matrix belongs to a 3×3 block (a node's axes, or three rod angles), so a left-looking
// factorization over block columns does the same flops as fixed-size 3×3 products, with one
// index per 9 values: 4x faster than CHOLMOD's on the toy ball's factorizations.
//
// It factors the filtered matrix K = S A S + (I - S) of the solver layer (S the diagonal 0/1
// mask of free axes; a free axis with a zero diagonal gets 1 too, as CHOLMOD's backends do),
// in a fill-reducing order (AMD on the block graph), the analysis kept while A's pattern is.

#include <cstdint>
#include <span>
#include <vector>

#include "sewn/physics/aligned.hpp"
#include "sewn/physics/block_matrix.hpp"

namespace sewn::physics::solve {

class BlockCholesky {
 public:
  /// Symbolic analysis of A's pattern: the ordering, L's block structure, the scatter of A's
  /// blocks. Kept until A's pattern_version() changes. O(blocks of L · log).
  void analyse(const BlockMatrix& A);
  /// True if analyse() ran on A's current pattern.
  [[nodiscard]] bool analysed_for(const BlockMatrix& A) const { return pattern_ != 0 && pattern_ == A.pattern_version(); }
  /// Flops of one numeric factorization (counted as a scalar LLᵀ's, 3×3 blocks dense).
  [[nodiscard]] double flops() const { return flops_; }
  /// Stored scalars of L (diagonal blocks' lower triangles and off-diagonal blocks).
  [[nodiscard]] double factor_entries() const { return 6.0 * static_cast<double>(perm_.size()) + 9.0 * static_cast<double>(row_.size()); }

  /// Numeric factorization of K (the header) for A's values, analysed first if its pattern is
  /// new. Throws SolverError (naming `who`, the node and the axis) where a pivot is not
  /// positive: K is not positive definite on the free axes. O(flops()).
  void factorize(const BlockMatrix& A, std::span<const double> free_dof, const char* who);
  /// out = K⁻¹ rhs (3n values each; may alias) with the last factor. O(entries of L).
  void solve(std::span<const double> rhs, std::span<double> out);

 private:
  void order(const BlockMatrix& A);
  void symbolic(const BlockMatrix& A);
  void scatter_column(const BlockMatrix& A, std::span<const double> free_dof, Index j);
  void update_column(Index j);
  void finish_column(Index j, const char* who);

  std::uint64_t pattern_ = 0;
  std::vector<Index> perm_, pinv_;  // pivot j is node perm_[j]; node i is pivot pinv_[i]
  // L's off-diagonal blocks by column: rows row_[col_[j] .. col_[j+1]) (ascending), values 9 each
  std::vector<std::size_t> col_;
  std::vector<Index> row_;
  // L's blocks by row: row j's run by_row_[j] .. by_row_[j+1) lists the columns k < j with
  // L(j,k) ≠ 0 (row_col_) and that block's position in row_ and lx_ (row_pos_)
  std::vector<std::size_t> by_row_, row_pos_;
  std::vector<Index> row_col_;
  // A's blocks scattered into column j of P A Pᵀ's lower triangle: slot in A, target pivot row
  std::vector<std::size_t> a_col_;
  std::vector<Index> a_slot_, a_row_;
  AlignedVector<double> lx_;    // off-diagonal blocks of L, column-major 3×3
  AlignedVector<double> dinv_;  // per pivot: the inverse of its diagonal block of L (lower)
  AlignedVector<double> w_;     // the dense column being factored: 9 per pivot row
  AlignedVector<double> y_;     // the permuted vector of solve()
  double flops_ = 0;
};

}  // namespace sewn::physics::solve
