#pragma once
// Internal: the fine level of sa-pcg's V-cycle and of its CG, on vectors padded to 4 doubles a
// node (the layout of the packed symmetric product of block-Jacobi CG, cg.hpp). The product
// y = S A p streams A's upper block triangle, 6 values a symmetric block: about half the bytes
// of the general 9-value product, and the kernel jacobi's CG uses. A matrix with a block that
// is not exactly symmetric (the exact viscous Jacobian of checks) falls back to A's own product.

#include <span>

#include "sewn/physics/aligned.hpp"
#include "sewn/physics/block_matrix.hpp"
#include "sewn/physics/cg.hpp"

namespace sewn::physics::solve::detail {

class FineLevel {
 public:
  /// The matrix of the solve about to run and its mask (1 free / 0 fixed per axis): packs A
  /// (pattern kept while A's is), and computes the filtered inverses of its diagonal blocks.
  /// A must outlive the solve. O(blocks).
  void bind(const BlockMatrix& A, std::span<const double> free_dof);
  [[nodiscard]] std::size_t nodes() const { return nodes_; }
  /// The mask padded: 4 a node, the fourth 0.
  [[nodiscard]] const double* free4() const { return free4_.data(); }
  /// y = S A p (padded vectors); returns p·y. O(blocks).
  double product(const double* p, double* y);
  /// d = S (keep d + scale D⁻¹ v), D⁻¹ the filtered inverses of A's diagonal blocks. O(nodes).
  void smooth_step(const double* v, double* d, double scale, double keep) const;
  /// Padded copies of 3-a-node vectors, and back (the padding is written 0 / skipped).
  static void pad(std::span<const double> v3, double* v4);
  static void unpad(const double* v4, std::span<double> v3);

 private:
  const BlockMatrix* A_ = nullptr;
  std::size_t nodes_ = 0;
  bool packed_ = false;
  CgWorkspace packed_ws_;  // the packed upper triangle (CgWorkspace's sym_* members)
  AlignedVector<double> free4_, inverse_, x3_, y3_;
};

}  // namespace sewn::physics::solve::detail
