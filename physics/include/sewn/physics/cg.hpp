#pragma once
// Preconditioned conjugate gradients with Baraff-Witkin filtering (PHYSICS_NOTES §1.5):
// constrained axes keep their prescribed values and never enter the Krylov space.

#include <span>

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

/// Work vectors reused between solves (no allocation once sized).
struct CgWorkspace {
  AlignedVector<double> r, z, p, q;
  void resize(std::size_t n3);
};

/// Solves A x = b on the free axes with x fixed to its incoming values on the others (pass
/// the warm start there too). Stops when the relative residual ≤ tolerance or after
/// max_iterations. O(iterations · blocks).
CgResult filtered_pcg(const BlockMatrix& A, std::span<const double> b, std::span<double> x,
                      std::span<const double> free_dof, std::span<const double> precond_inverse, double tolerance,
                      int max_iterations, CgWorkspace& ws);

}  // namespace sewn::physics
