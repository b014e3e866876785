#pragma once
// BlockMatrix: an n×n matrix of 3×3 blocks in compressed-row form (every diagonal block
// present, off-diagonal blocks in symmetric pairs (i,j)/(j,i)). The pattern is built once from
// the node pairs the force terms couple and reused until their topology changes; terms cache
// the slot of each block they write, so assembly never searches.

#include <cstdint>
#include <span>
#include <vector>

#include <Eigen/Core>
#include <Eigen/SparseCore>

#include "sewn/physics/aligned.hpp"
#include "sewn/physics/types.hpp"

namespace sewn::physics {

/// Two distinct nodes coupled by some element.
struct NodePair {
  Index i, j;
};

class BlockMatrix {
 public:
  using BlockMap = Eigen::Map<Eigen::Matrix3d>;
  using ConstBlockMap = Eigen::Map<const Eigen::Matrix3d>;

  /// Builds the pattern for n nodes: every diagonal block and, for each pair, blocks (i,j) and
  /// (j,i) (duplicates merged). Values become zero. Throws InputError on an index ≥ n or i == j.
  /// Invalidates block slots cached by terms (pattern_version() changes). O(n + p log p).
  void build_pattern(Index n, std::span<const NodePair> pairs);
  /// Number of block rows (nodes). O(1).
  [[nodiscard]] Index size() const { return n_; }
  /// Number of stored 3×3 blocks. O(1).
  [[nodiscard]] Index num_blocks() const { return static_cast<Index>(col_.size()); }
  /// Slot of block (i,j), or invalid_index if it is not in the pattern. O(log row length).
  [[nodiscard]] Index find(Index i, Index j) const;
  /// Slot of diagonal block (i,i). O(1).
  [[nodiscard]] Index diagonal(Index i) const { return diag_[i]; }
  /// Block at a slot, column-major 3×3. No bounds check (slots come from find/diagonal).
  [[nodiscard]] BlockMap block(Index slot) { return BlockMap(val_.data() + 9 * std::size_t{slot}); }
  [[nodiscard]] ConstBlockMap block(Index slot) const { return ConstBlockMap(val_.data() + 9 * std::size_t{slot}); }
  [[nodiscard]] double* block_data(Index slot) { return val_.data() + 9 * std::size_t{slot}; }
  [[nodiscard]] std::span<const Index> row_offsets() const { return row_; }
  [[nodiscard]] std::span<const Index> columns() const { return col_; }
  /// Zeroes every value, keeping the pattern; rows split over threads as in multiply(). O(blocks).
  void set_zero();
  /// y = A x for 3n vectors, rows split over thread_count() threads (threads.hpp); the
  /// result is the same bitwise for every count. O(blocks).
  void multiply(std::span<const double> x, std::span<double> y) const;
  /// Rows [first, last) of y = A x, on the calling thread. O(blocks of those rows).
  void multiply_rows(std::span<const double> x, std::span<double> y, Index first, Index last) const;
  /// Rows per thread below which multiply() uses fewer threads.
  static constexpr Index multiply_grain = 512;
  /// The same matrix as an Eigen sparse matrix (3n×3n), for tests and direct solvers. O(blocks).
  [[nodiscard]] Eigen::SparseMatrix<double> to_sparse() const;
  /// Changes whenever build_pattern() runs, unique across all matrices (0: never built); terms
  /// and solvers compare it to know their cached slots or analyses are stale.
  [[nodiscard]] std::uint64_t pattern_version() const { return version_; }

 private:

  Index n_ = 0;
  std::vector<Index> row_, col_, diag_;
  AlignedVector<double> val_;
  std::uint64_t version_ = 0;
};

}  // namespace sewn::physics
