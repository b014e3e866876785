#pragma once
// Shared vocabulary of per-element energies (solids/, shells/): fixed-size vectors and
// matrices of an element's degrees of freedom, the PSD projection Newton needs, and the
// constant matrix that maps node positions to a linear element's deformation gradient.
//
// DOF order of every element: node-major, [x0 y0 z0 x1 y1 z1 ...], matching the node table.

#include <Eigen/Core>
#include <Eigen/Geometry>

namespace sewn::physics::elements {

template <int N>
using Vec = Eigen::Matrix<double, N, 1>;
template <int N>
using Mat = Eigen::Matrix<double, N, N>;

/// Replaces H (symmetric, any size) by its nearest positive-semidefinite matrix in the
/// Frobenius norm: eigenvalues below zero are clamped to zero. Returns the most negative
/// eigenvalue seen (0 if none). Cost: one symmetric eigendecomposition, O(N³) (12×12: a few
/// microseconds); returns at once when diagonal dominance already proves H PSD.
/// One dynamic-size implementation serves every element size (6 to 18 DOFs): a fixed-size
/// eigensolver per size cost seconds of compile time each, for 9-26 % less time per call.
double project_psd(Eigen::Ref<Eigen::MatrixXd> H);

/// The cofactor matrix of A, ∂det(A)/∂A: columns a₁×a₂, a₂×a₀, a₀×a₁. O(1).
inline Eigen::Matrix3d cofactor(const Eigen::Matrix3d& A) {
  Eigen::Matrix3d C;
  C.col(0) = A.col(1).cross(A.col(2));
  C.col(1) = A.col(2).cross(A.col(0));
  C.col(2) = A.col(0).cross(A.col(1));
  return C;
}

}  // namespace sewn::physics::elements
