#pragma once
// Per-element elasticity of a linear tetrahedron (PHYSICS_NOTES §3.3): value, gradient and
// exact Hessian of the stored energy V̄·Ψ(F) on fixed-size Eigen types.
//
// Stencil: the 4 nodes of the tetrahedron. DOF order: [x0 y0 z0 x1 ... z3] (12). Positions
// are passed as a 3×4 matrix whose column i is node i.
// Kinematics: Dm = [X1-X0, X2-X0, X3-X0] (rest), Ds likewise (current), F = Ds·Dm⁻¹,
// V̄ = |det Dm|/6.
// Laws (Ψ per unit rest volume):
//   stvk                Ψ = μ E:E + ½λ (tr E)², E = ½(FᵀF - I). Zero energy at a reflection
//                       and softening past s = 1/√3 in compression (§3.3): not inversion-safe.
//   stable_neo_hookean  Ψ = ½μ (tr FᵀF - 3) + ½λ' ((J - α)² - (1 - α)²), J = det F, λ' = λ + μ,
//                       α = 1 + μ/λ' (Smith, de Goes, Kim 2018, the form without the log term):
//                       stress-free at F = I, the same linearisation as StVK (Lamé μ, λ),
//                       finite and smooth through J = 0, with positive energy at a reflection,
//                       so inverted elements are pushed back.
// Cost per element: energy ~60 flops; gradient ~150; Hessian ~3k (9×9 tangent, then
// Bᵀ(∂P/∂F)B) plus, in the force terms, an optional PSD projection (elements::project_psd).

#include <Eigen/Core>

#include "sewn/physics/elements/element_math.hpp"

namespace sewn::physics::solids {

using TetPositions = Eigen::Matrix<double, 3, 4>;
using Vec12 = elements::Vec<12>;
using Mat12 = elements::Mat<12>;

/// Lamé parameters (Pa).
struct Lame {
  double mu = 0.0;
  double lambda = 0.0;
};

/// μ = E/(2(1+ν)), λ = Eν/((1+ν)(1-2ν)). Throws InputError unless E > 0 and -1 < ν < ½ (finite).
[[nodiscard]] Lame lame_from_young(double young, double poisson);

/// Rest data of one tetrahedron.
struct TetRest {
  Eigen::Matrix3d Dm = Eigen::Matrix3d::Identity();  ///< rest edges [X1-X0, X2-X0, X3-X0]
  Eigen::Matrix3d Dm_inv = Eigen::Matrix3d::Identity();
  double volume = 0.0;  ///< V̄ = |det Dm| / 6
};

/// Rest data from rest positions. Throws InputError (naming the volume and the longest edge)
/// if the tetrahedron is degenerate: V̄ ≤ 1e-12·(longest edge)³ or not finite.
[[nodiscard]] TetRest tet_rest(const TetPositions& X);

enum class TetLaw { stvk, stable_neo_hookean };

/// Current deformation gradient F = Ds·Dm⁻¹. O(1).
[[nodiscard]] Eigen::Matrix3d deformation_gradient(const TetPositions& x, const TetRest& rest);
/// H = F - I computed as (Ds - Dm)·Dm⁻¹, free of the cancellation in F - I: energies are
/// evaluated from it, so that a stiff element's energy carries round-off of the size of its
/// strain, not of its modulus (Newton's line search compares energies). O(1).
[[nodiscard]] Eigen::Matrix3d displacement_gradient(const TetPositions& x, const TetRest& rest);

/// Ψ, first Piola stress P = ∂Ψ/∂F and its derivative ∂vec(P)/∂vec(F) (9×9, vec
/// column-major) for a law. energy_density takes the displacement gradient H = F - I.
[[nodiscard]] double energy_density(TetLaw law, const Eigen::Matrix3d& H, const Lame& m);
[[nodiscard]] Eigen::Matrix3d first_piola(TetLaw law, const Eigen::Matrix3d& F, const Lame& m);
[[nodiscard]] elements::Mat<9> piola_derivative(TetLaw law, const Eigen::Matrix3d& F, const Lame& m);
/// A PSD stand-in for piola_derivative with no 9×9 eigensolver.
/// stable_neo_hookean: the nearest PSD matrix itself, from the tangent's closed-form
/// eigensystem in the signed SVD F = U diag(σ) Vᵀ: μ ± λ'(J-α)σ_k on the twists and flips
/// U (e_i e_jᵀ ∓ e_j e_iᵀ) Vᵀ/√2, and a 3×3 block on the scalings U diag(e) Vᵀ; negative
/// eigenvalues are clamped to zero. stvk: the geometric term dF·S with S clamped to S⁺ ≥ 0 per
/// principal stress (the material term is PSD), exact under tension, PSD by construction.
/// piola_derivative is returned unchanged where it is PSD (neo-Hookean) or where all principal
/// stresses are ≥ 0 (StVK). Cost: a 3×3 SVD or eigensolve.
[[nodiscard]] elements::Mat<9> piola_derivative_psd(TetLaw law, const Eigen::Matrix3d& F, const Lame& m);

/// V̄·Ψ, its gradient (12) and its Hessian (12×12, exact, symmetric, possibly indefinite).
[[nodiscard]] double tet_energy(TetLaw law, const TetPositions& x, const TetRest& rest, const Lame& m);
[[nodiscard]] Vec12 tet_gradient(TetLaw law, const TetPositions& x, const TetRest& rest, const Lame& m);
[[nodiscard]] Mat12 tet_hessian(TetLaw law, const TetPositions& x, const TetRest& rest, const Lame& m);
/// V̄ Bᵀ piola_derivative_psd B: PSD (B constant), the exact Hessian wherever the tangent is
/// PSD, with no 12×12 eigendecomposition (what Newton's projected Jacobians use).
[[nodiscard]] Mat12 tet_hessian_psd(TetLaw law, const TetPositions& x, const TetRest& rest, const Lame& m);

}  // namespace sewn::physics::solids
