#pragma once
// Internal: the hierarchy of the sa-pcg backend, aggregation multigrid built on the rigid-body
// modes, and its symmetric V-cycle. Our own method, after the classical smoothed-aggregation
// recipe: aggregates of strongly coupled neighbouring nodes; on each aggregate the near-null
// space (three translations and three rotations of its nodes at the fine level; the coarse
// representation of those six modes further down) orthonormalised into the tentative
// prolongator T; the Galerkin coarse matrix Pᵀ K P; recursively until a level is small enough
// for a dense Cholesky. P = (I - ω D⁻¹ K) T, the smoothing that gives the method its name, is
// built in but off: measured, it made the coarse matrices denser than the fine one for no
// fewer iterations once the fine level is smoothed well (aggregation.cpp). The fine level is
// smoothed by a Chebyshev polynomial in D⁻¹K (D: its 3×3 diagonal blocks), the coarse ones by
// one damped block-Jacobi sweep, the same before and after: the V-cycle is symmetric.
//
// Level 0 is the filtered fine matrix K = S A S + (I - S). The V-cycle applies it through A
// itself (FineLevel: the packed symmetric product, on vectors padded to 4 doubles a node) so
// that the fine smoothing follows the matrix of the current solve while the coarse levels, set
// up on an earlier one, are kept (kept_pcg.hpp). The coarse matrices use 32-bit indices: their
// products stream fewer bytes.

#include <cstdint>
#include <span>
#include <vector>

#include <Eigen/Cholesky>
#include <Eigen/Core>
#include <Eigen/SparseCore>

#include "sewn/physics/aligned.hpp"
#include "sewn/physics/block_matrix.hpp"
#include "fine_level.hpp"

namespace sewn::physics::solve::detail {

using RowSparse = Eigen::SparseMatrix<double, Eigen::RowMajor, int>;

/// One level below the fine one: its matrix, the block-diagonal inverse of its smoother (one
/// dense block per coarse node, i.e. per aggregate of the level above, of 1 to 6 unknowns) and
/// the prolongator from it to the level above.
struct CoarseLevel {
  RowSparse K;                      // Galerkin matrix of this level
  std::vector<std::int64_t> first;  // unknowns of node i: [first[i], first[i + 1])
  std::vector<double> inverse;      // the nodes' inverse diagonal blocks, row-major, concatenated
  std::vector<std::int64_t> inverse_at;
  RowSparse P, Pt;                  // prolongator from this level to the one above, and its transpose
                                    // (from level 1 to 0: rows indexed as padded fine vectors, 4i + a)
  double omega = 0;                 // smoother damping of this level (4 / (3 ρ(D⁻¹K)))
};

/// What the hierarchy is built from: the fine matrix's values (filtered, 9 per block of A's
/// pattern), the mask, and the nodes' coordinates (3 per node; empty: translations only).
struct FineInput {
  std::span<const Index> rows, columns;
  std::span<const double> values, free_dof, coordinates;
};

class SaHierarchy {
 public:
  /// Builds every level from `in`. Throws SolverError naming `who` if a diagonal block or the
  /// coarsest matrix is not positive definite. O(entries of K and of the products).
  void build(const FineInput& in, const char* who);
  void clear();
  [[nodiscard]] bool empty() const { return levels_.empty() && fine_omega_ == 0; }
  /// z = one symmetric V-cycle on r (K⁻¹ approximated), padded vectors (4 a node, r zero on
  /// the fixed axes and the padding), the fine level applied through `fine` (the current
  /// solve's matrix). No allocation once the work vectors are sized.
  void vcycle(FineLevel& fine, const double* r, double* z);
  [[nodiscard]] std::size_t levels() const { return levels_.size() + 1; }
  /// Unknowns per level, fine first (for reports and tests).
  [[nodiscard]] std::vector<std::int64_t> sizes() const;
  /// Stored entries of every level's matrix and prolongator (the V-cycle's work is about this).
  [[nodiscard]] double cycle_entries() const;

 private:
  void descend(std::size_t l);  // the V-cycle below the fine level, from rc_[l] into zc_[l]
  std::vector<CoarseLevel> levels_;
  std::int64_t fine_unknowns_ = 0;
  double fine_omega_ = 0, fine_entries_ = 0;
  Eigen::LLT<Eigen::MatrixXd> coarsest_;
  bool coarsest_dense_ = false;  // the last level is factored in coarsest_ (else smoothed only)
  // work vectors of the V-cycle, per level
  std::vector<Eigen::VectorXd> rc_, zc_, tc_, uc_;
  AlignedVector<double> t0_, u0_, d0_;
};

}  // namespace sewn::physics::solve::detail
