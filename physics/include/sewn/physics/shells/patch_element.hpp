#pragma once
// Patch bending of thin shells: per triangle, the plate energy of the quadratic that fits the
// triangle's patch (its 3 corners and the node opposite each interior edge), written in the
// edges' dihedral angles so that it is invariant under rigid motions. The default bending
// model of shells; the hinge model (hinge_element.hpp) does not converge on meshes whose
// diagonals run one way (docs/elastic.md has the derivation and the measured tables).
//
// Energy of triangle T (rest area Ā, plate stiffness D = E h³/(12(1-ν²)), Poisson ν):
//   E_T = Ā · (D/2) [(1-ν) tr(K²) + ν (tr K)²],  K = Σ_m β_m ∇²b_m   (2×2, rest plane of T)
// with b_m = λ_{m+1}λ_{m+2} the quadratic bubble of edge m (λ: T's barycentric coordinates)
// and β the coefficients of the quadratic that vanishes at T's corners and, at each interior
// edge k's unfolded opposite node q_k, equals its height above T's plane, d_k = ℓ_k (θ_k - θ̄_k)
// to first order (ℓ_k: the rest distance of that node from the edge, θ_k: the dihedral angle of
// hinge_element.hpp). On an edge with no neighbour (a free boundary) β is free and the energy
// takes its minimum over it, the natural condition of a free edge (zero bending moment).
// A clamped edge (its neighbour is a held triangle, a clamp) constrains the slope instead: the
// quadratic's normal derivative at the edge's midpoint equals the clamp plane's slope,
// d_k = θ_k - θ̄_k (lever 1), which puts the clamp exactly on the edge (holding the
// neighbour's node at its height would put it half a cell outside).
// Eliminating β once at rest leaves E_T = ½ dᵀ S d with a constant K×K matrix S (K interior
// edges), S = (C Q⁻¹ Cᵀ)⁻¹, C_km = b_m(q_k), Q the energy's matrix in β.
// Consistency: for a flat sheet deflected by any quadratic w, K is w's Hessian exactly, on any
// mesh whose patches are not on a conic, so the energy converges to the plate's; the hinge
// energy's triangle-wise counterpart is not exact on structured meshes (docs/elastic.md).
//
// Stencil: N = 3 + K nodes, T's corners (counter-clockwise seen along T's normal) then the
// opposite node of each interior edge in the order of `PatchRest::edge`; DOF order
// [x0 y0 z0 x1 ...] (3N). Cost: energy ~K·100 flops, gradient ~K·150, Hessian ~K·1.2k
// (each edge's closed-form angle Hessian, dihedral_derivatives) plus (3N)² for the outer products.

#include <array>
#include <cstdint>

#include <Eigen/Core>

#include "sewn/physics/elements/element_math.hpp"

namespace sewn::physics::shells {

/// Plate bending stiffness D and Poisson ratio of a shell's material.
struct PlateMaterial {
  double stiffness = 0.0;  ///< D = E h³/(12(1-ν²)), N·m
  double poisson = 0.0;
};

/// Throws InputError unless E > 0, -1 < ν < ½, h > 0 (all finite).
[[nodiscard]] PlateMaterial plate_material(double young, double poisson, double thickness);

struct PatchRest {
  int count = 0;                       ///< K, interior edges (1..3)
  std::array<std::uint8_t, 3> edge{};  ///< per stencil neighbour k: T's edge, named by its opposite corner
  std::array<double, 3> theta{};       ///< θ̄_k, rad
  std::array<double, 3> lever{};       ///< ℓ_k, m (1 for a clamped edge)
  std::array<std::uint8_t, 3> clamped{};  ///< per neighbour: 1 if it is a clamp (slope constraint)
  Eigen::Matrix3d stiffness = Eigen::Matrix3d::Zero();  ///< S (top-left K×K), N/m
};

template <int N>
using PatchPositions = Eigen::Matrix<double, 3, N>;

/// Rest data of a patch of N = 3 + K nodes (K = 1..3) whose neighbour k lies across T's edge
/// `edges[k]` (the edge opposite that corner; distinct); `clamped[k]` != 0 makes neighbour k a
/// clamp (its triangle held: the slope across the edge is constrained). Throws InputError on a degenerate
/// triangle or neighbour, repeated edges, or a patch whose nodes lie on a conic (no unique
/// quadratic; the message names the edges).
template <int N>
[[nodiscard]] PatchRest patch_rest(const PatchPositions<N>& X, const std::array<std::uint8_t, N - 3>& edges,
                                   const std::array<std::uint8_t, N - 3>& clamped, const PlateMaterial& m);

template <int N>
[[nodiscard]] double patch_energy(const PatchPositions<N>& x, const PatchRest& rest);
template <int N>
[[nodiscard]] elements::Vec<3 * N> patch_gradient(const PatchPositions<N>& x, const PatchRest& rest);
/// patch_energy, with patch_gradient written to g, from one evaluation of the dihedral angles.
template <int N>
[[nodiscard]] double patch_energy_gradient(const PatchPositions<N>& x, const PatchRest& rest, elements::Vec<3 * N>& g);
/// Exact Hessian (symmetric, indefinite in general).
template <int N>
[[nodiscard]] elements::Mat<3 * N> patch_hessian(const PatchPositions<N>& x, const PatchRest& rest);
/// ∇θ and ∇²θ of one hinge (dihedral_derivatives, hinge_element.hpp), as computed for the node
/// order (x0, x1, x2, x3) of one patch's view of the edge: the patch across the edge sees it as
/// (x3, x2, x1, x0), with the same angle and the same derivatives, blocks in reverse order.
struct HingeDerivatives {
  elements::Vec<12> g;
  elements::Mat<12> H;
};
/// Where patch_hessian_shared takes hinge k's derivatives from: `of[k]`, computed in this
/// patch's node order for hinge k, or in the reverse order where reversed[k].
struct SharedHinges {
  std::array<const HingeDerivatives*, 3> of{};
  std::array<bool, 3> reversed{};
};
/// patch_hessian with the hinges' derivatives given (computed once per edge for both its
/// patches: PatchBending::for_each_hessian); equal to patch_hessian up to round-off.
template <int N>
[[nodiscard]] elements::Mat<3 * N> patch_hessian_shared(const PatchPositions<N>& x, const PatchRest& rest,
                                                       const SharedHinges& hinges);
/// The Gauss-Newton part of the Hessian, JᵀSJ (J's row k = ℓ_k ∇θ_k): PSD by construction
/// (S is positive definite), with no angle Hessian and no eigendecomposition. It drops the
/// curvature terms Σ_k (S d)_k ℓ_k ∇²θ_k, so it is exact where every d_k = 0 (the rest angles)
/// and Newton's steps with it are Gauss-Newton steps (the gradient is unchanged).
template <int N>
[[nodiscard]] elements::Mat<3 * N> patch_hessian_gauss_newton(const PatchPositions<N>& x, const PatchRest& rest);

}  // namespace sewn::physics::shells
