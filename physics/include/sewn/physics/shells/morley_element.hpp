#pragma once
// Morley bending of thin shells: per triangle, the plate energy of Morley's nonconforming
// quadratic (the deflection at the corners plus one normal slope per edge midpoint), written
// in angles so that it holds at large deflections and is invariant under rigid motions. Each
// edge carries one angle DOF ψ (System::angles(), like a rod's twist): the rotation, about the
// edge, of the edge's mid-normal away from its rest position relative to the edge's owner
// triangle (the first of its two). Unlike patch bending (patch_element.hpp) it converges on
// irregular meshes: Morley's element is the classical convergent nonconforming plate element
// (docs/elastic.md has the measured orders).
//
// Slopes. For triangle T and its edge i (opposite corner i), s_i is the angle of the edge's
// mid-normal relative to T, positive when it tilts towards T's normal going outwards across
// the edge; its change from rest Δs_i is, by the edge's kind:
//   own    (T owns the edge, or the edge is a free boundary)  Δs_i = ψ_i
//   other  (the edge's owner is the neighbour)                Δs_i = Δφ_i - ψ_i
//   clamp  (the neighbour is a held triangle)                 Δs_i = Δφ_i
// with φ_i = -θ_i the bending angle of the hinge (T, neighbour) of hinge_element.hpp (the
// neighbour's tilt towards T's normal; Δφ wrapped into (-π, π]). The owner sees the mid-normal
// at ψ, the other triangle at its own tilt minus ψ: both agree on one mid-normal, and at rest
// ψ = 0 is the bisector. A clamp holds the mid-normal at the held triangle's normal, which puts
// the clamp exactly on the edge.
//
// Energy of T (rest area Ā, plate stiffness D, Poisson ν):
//   E_T = Ā (D/2) [(1-ν) tr(K²) + ν (tr K)²],  K = Σ_m c_m ∇²b_m  (2×2, T's rest plane)
// with b_m = λ_{m+1}λ_{m+2} the bubble of edge m and c the bubble coefficients of the
// quadratic that vanishes at T's corners and has outward normal slope Δs_i at edge i's
// midpoint: ∂b_m/∂n_i there is (ℓ_i/4Ā)(δ_mi − [m≠i]), so c_m = −(2Ā)(Δs_j/ℓ_j + Δs_k/ℓ_k)
// ({m, j, k} = {0, 1, 2}). Hence E_T = ½ Δsᵀ S Δs, S = Gᵀ Q G constant (3×3, SPD).
// Linearised about a flat sheet this is exactly Morley's element; for every quadratic
// deflection it gives the plate's energy on any mesh.
//
// Stencil: 6 node slots and 3 angle slots, DOF order [x0 y0 z0 … x5 y5 z5 ψ0 ψ1 ψ2] (21):
// T's corners 0..2 (counter-clockwise seen along T's normal), slot 3 + i the node across edge
// i (used by kinds other and clamp; unused slots and angles have zero rows). Cost: energy ~300
// flops, gradient ~400, Hessian ~2 angle Hessians (AutoDiff, ~2.5k flops each) plus 21² outer
// products.

#include <array>
#include <cstdint>

#include <Eigen/Core>

#include "sewn/physics/elements/element_math.hpp"
#include "sewn/physics/shells/patch_element.hpp"

namespace sewn::physics::shells {

enum class MorleyEdge : std::uint8_t { own = 0, other = 1, clamp = 2 };

struct MorleyRest {
  std::array<MorleyEdge, 3> kind{};  ///< per edge i (opposite corner i)
  std::array<double, 3> theta{};     ///< θ̄_i of the hinge (kinds other, clamp), rad
  Eigen::Matrix3d stiffness = Eigen::Matrix3d::Zero();  ///< S, N·m
};

using MorleyPositions = Eigen::Matrix<double, 3, 6>;
using MorleyVec = elements::Vec<21>;
using MorleyMat = elements::Mat<21>;

/// Rest data: X's columns 0..2 the triangle, column 3 + i the node across edge i where
/// kind[i] is other or clamp (ignored otherwise). Throws InputError on a degenerate triangle
/// or hinge, or a bad material.
[[nodiscard]] MorleyRest morley_rest(const MorleyPositions& X, const std::array<MorleyEdge, 3>& kind, const PlateMaterial& m);

/// The slope changes Δs (see above) at positions x and edge angles psi.
[[nodiscard]] Eigen::Vector3d morley_slopes(const MorleyPositions& x, const Eigen::Vector3d& psi, const MorleyRest& rest);
[[nodiscard]] double morley_energy(const MorleyPositions& x, const Eigen::Vector3d& psi, const MorleyRest& rest);
[[nodiscard]] MorleyVec morley_gradient(const MorleyPositions& x, const Eigen::Vector3d& psi, const MorleyRest& rest);
/// Exact Hessian (symmetric, indefinite in general).
[[nodiscard]] MorleyMat morley_hessian(const MorleyPositions& x, const Eigen::Vector3d& psi, const MorleyRest& rest);

}  // namespace sewn::physics::shells
