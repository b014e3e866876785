#pragma once
// Preconditioned conjugate gradients with Baraff-Witkin filtering (PHYSICS_NOTES §1.5):
// constrained axes keep their prescribed values and never enter the Krylov space.

#include <cstdint>
#include <span>
#include <vector>

#include "sewn/physics/aligned.hpp"
#include "sewn/physics/block_matrix.hpp"

namespace sewn::physics {

struct CgResult {
  int iterations = 0;
  double relative_residual = 0.0;  ///< ‖S(b - Ax)‖₂ / ‖Sb‖₂ (recursive residual)
  bool converged = false;
  bool breakdown = false;          ///< pᵀAp ≤ 0: the filtered matrix is not positive definite
};

/// Inverses of the filtered 3×3 diagonal blocks, (S A_ii S + I - S)⁻¹, 9 per node
/// (column-major), for block-Jacobi preconditioning. free_dof is 1 on free axes, 0 on fixed. O(n).
void block_jacobi_inverse(const BlockMatrix& A, std::span<const double> free_dof, std::span<double> inverse);
/// The same for given 3×3 blocks (column-major, 9 per node), e.g. those of a reduced system. O(n).
void block_jacobi_inverse(std::span<const double> blocks, std::span<const double> free_dof, std::span<double> inverse);

/// Work arrays reused between solves (no allocation once sized).
struct CgWorkspace {
  AlignedVector<double> r, z, p, q;
  void resize(std::size_t n3);

  // The fast path (AVX-512 builds, every block of A symmetric, as the springs' are): the upper
  // block triangle of A, 6 values per symmetric 3×3 block, less than half the bytes of A, so
  // that a product streams from L2 for meshes whose full matrix does not fit there. Rows of
  // vectors are padded to 4 doubles. The pattern is rebuilt when A's pattern_version() changes.
  std::uint64_t sym_pattern = ~std::uint64_t{0};
  std::vector<Index> sym_row, sym_col, sym_src;  // row offsets (diagonal first), columns, slots in A
  AlignedVector<double> sym_val;                  // 6 per block: a00 a01 a02 a11 a12 a22
  AlignedVector<double> x4, free4;                // 4 per node
  AlignedVector<double> pre;                      // the filtered preconditioner, 6 per node
  AlignedVector<double> expanded, ones4;          // a reduced solve's W p, and a filter of ones
  // Several threads: thread t's products into rows past its own range, one array per thread
  // (4 per node, rows [end of t's range, spill_end[t]) used, all zero between products), added
  // in thread order (deterministic); rows from first_final[t] on receive none. Planned per
  // packed pattern and count.
  std::vector<AlignedVector<double>> spill;
  std::vector<std::size_t> spill_end, first_final;
  std::uint64_t spill_pattern = ~std::uint64_t{0};
  int spill_parts = 0;
};

/// The fast path's packed matrix for other solvers (sa-pcg's multigrid and its CG): copies A's
/// upper block triangle into ws (its pattern rebuilt only when A's changes). Returns false, ws
/// unusable, if a block of A is not exactly symmetric. O(blocks).
bool pack_symmetric_blocks(const BlockMatrix& A, CgWorkspace& ws);
/// y = S A p on vectors padded to 4 doubles a node (padding zero), S the padded mask free4;
/// returns p·y. Pre: pack_symmetric_blocks(A, ws) returned true. One thread. O(blocks).
double packed_symmetric_product(const CgWorkspace& ws, const double* p, double* y, const double* free4, Index nodes);

/// W and Wᵀ of a reduced system on node vectors padded to 4 doubles (SlaveNodes: the
/// T-junctions' interpolation): expand4 sets each slave's row from its masters, reduce4 adds it
/// to them and zeroes it.
class PaddedReduction {
 public:
  virtual void expand4(double* v) const = 0;
  virtual void reduce4(double* v) const = 0;

 protected:
  ~PaddedReduction() = default;
};

/// The packed fast path of filtered_pcg (one thread) on the reduced system S Wᵀ A W S, W's
/// products folded into each matrix product: rb = S Wᵀ b, free_dof 0 on the slaves' axes too,
/// x the warm start (its slave rows are overwritten by nothing: expand x afterwards). Returns
/// false, x untouched, when that path cannot run (a build without AVX-512, or a block of A not
/// exactly symmetric): the caller then solves another way. O(iterations · blocks).
bool reduced_pcg_packed(const BlockMatrix& A, std::span<const double> rb, std::span<double> x,
                        std::span<const double> free_dof, std::span<const double> precond_inverse, double tolerance,
                        int max_iterations, CgWorkspace& ws, const PaddedReduction& W, CgResult& out);

/// Solves A x = b on the free axes with x fixed to its incoming values on the others (pass
/// the warm start there too). Stops when ‖S(b - Ax)‖ ≤ max(tolerance · ‖Sb‖, absolute_floor)
/// or after max_iterations. O(iterations · blocks).
CgResult filtered_pcg(const BlockMatrix& A, std::span<const double> b, std::span<double> x,
                      std::span<const double> free_dof, std::span<const double> precond_inverse, double tolerance,
                      int max_iterations, CgWorkspace& ws, double absolute_floor = 0.0);

}  // namespace sewn::physics
