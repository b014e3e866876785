#pragma once
// Constant-strain-triangle membrane with Green strain, St. Venant-Kirchhoff in plane stress
// (PHYSICS_NOTES §3.2): value, gradient and exact Hessian on fixed-size Eigen types.
//
// Stencil: the 3 nodes of the triangle. DOF order: [x0 y0 z0 x1 ... z2] (9); positions as a
// 3×3 matrix whose column i is node i.
// Energy: W = h·Ā·[μ tr(E²) + ½λ_ps (tr E)²], E = ½(FᵀF - I₂), F = Ds·Dm⁻¹ (3×2), Dm the
// rest edges [X1-X0, X2-X0] in an orthonormal frame of the rest triangle, μ = E/(2(1+ν)),
// λ_ps = Eν/(1-ν²). Green strain makes W invariant under rigid motions (no ghost forces).
// Cost: energy ~50 flops, gradient ~100, Hessian ~0.4k (block by block, membrane_element.cpp).

#include <Eigen/Core>

#include "sewn/physics/elements/element_math.hpp"

namespace sewn::physics::shells {

using TriPositions = Eigen::Matrix<double, 3, 3>;
using Vec9 = elements::Vec<9>;
using Mat9 = elements::Mat<9>;

/// Plane-stress membrane constants, thickness included.
struct MembraneMaterial {
  double mu = 0.0;         ///< shear modulus, Pa
  double lambda_ps = 0.0;  ///< plane-stress Lamé parameter Eν/(1-ν²), Pa
  double thickness = 0.0;  ///< m
};

/// Throws InputError unless E > 0, -1 < ν < ½ and thickness > 0 (all finite).
[[nodiscard]] MembraneMaterial membrane_material(double young, double poisson, double thickness);

struct TriRest {
  Eigen::Matrix<double, 3, 2> edges = Eigen::Matrix<double, 3, 2>::Zero();  ///< rest [X1-X0, X2-X0]
  Eigen::Matrix2d Dm_inv = Eigen::Matrix2d::Identity();
  double area = 0.0;  ///< Ā
};

/// Rest data from rest positions. Throws InputError if Ā ≤ 1e-12·(longest edge)² or not finite.
[[nodiscard]] TriRest tri_rest(const TriPositions& X);

/// F (3×2) of the current positions.
[[nodiscard]] Eigen::Matrix<double, 3, 2> membrane_deformation(const TriPositions& x, const TriRest& rest);

/// Green strain E = ½ Dm⁻ᵀ(UᵀX + XᵀU + UᵀU)Dm⁻¹, U = Ds - X the change of the edges X: free
/// of the cancellation in FᵀF - I, so that a stiff membrane's energy carries round-off of the
/// size of its strain (Newton's line search compares energies).
[[nodiscard]] Eigen::Matrix2d membrane_strain(const TriPositions& x, const TriRest& rest);

[[nodiscard]] double membrane_energy(const TriPositions& x, const TriRest& rest, const MembraneMaterial& m);
[[nodiscard]] Vec9 membrane_gradient(const TriPositions& x, const TriRest& rest, const MembraneMaterial& m);
/// membrane_energy, with membrane_gradient written to g, from one strain evaluation.
[[nodiscard]] double membrane_energy_gradient(const TriPositions& x, const TriRest& rest, const MembraneMaterial& m, Vec9& g);
/// Exact Hessian (symmetric, possibly indefinite under compression).
[[nodiscard]] Mat9 membrane_hessian(const TriPositions& x, const TriRest& rest, const MembraneMaterial& m);
/// A PSD Hessian for Newton without an eigendecomposition of the 9×9: the exact Hessian with
/// the stress of its geometric term (dF·S) clamped per principal stress to S⁺ ≥ 0 (2×2, closed
/// form). Equal to membrane_hessian when both principal stresses are ≥ 0 (stretch); under
/// compression it drops the negative part of the geometric stiffness. Not the nearest PSD
/// matrix to the exact Hessian, but PSD by construction. Cost ~ membrane_hessian.
[[nodiscard]] Mat9 membrane_hessian_psd(const TriPositions& x, const TriRest& rest, const MembraneMaterial& m);

}  // namespace sewn::physics::shells
