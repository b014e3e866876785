#pragma once
// Force terms of patch bending (shells/patch_element.hpp), one per stencil size: a triangle
// with K interior edges is an element of PatchBending<3 + K>; a triangle with none has no
// bending energy of its own (its neighbours' patches hold its nodes). add_patch_bending builds
// all three from a triangle list, each paid for only when some triangle needs it.
// Forces = -gradient; ∂F/∂x = -Hessian (exact, or PSD-projected per element when
// JacobianOptions::project_element_hessians is set: the Gauss-Newton part, PSD by
// construction); no damping of their own.
// Cost per triangle: forces ~0.5 µs, exact Jacobians ~10 µs (three angle Hessians, each
// interior edge's computed once for the two patches of a term that share it:
// for_each_hessian), projected ones far less (three angle gradients and JᵀSJ, no
// eigen-projection).

#include <array>
#include <cstdint>
#include <span>
#include <string_view>
#include <vector>

#include "sewn/physics/elements/stencil_term.hpp"
#include "sewn/physics/shells/patch_element.hpp"
#include "sewn/physics/system.hpp"

namespace sewn::physics::shells {

template <int N>
class PatchBending final : public elements::StencilTerm<N> {
 public:
  using typename elements::StencilTerm<N>::Nodes;
  using typename elements::StencilTerm<N>::Positions;
  using typename elements::StencilTerm<N>::Gradient;
  using typename elements::StencilTerm<N>::Hessian;

  [[nodiscard]] std::string_view name() const override;
  /// Adds triangle nodes[0..2] (counter-clockwise) with the node across each of its edges
  /// `edges[k]` (named by the opposite corner) as nodes[3 + k], a clamp where clamped[k] != 0;
  /// X the rest positions (column i for nodes[i]). Throws InputError (unchanged, naming the element) on a repeated node,
  /// bad material or a patch patch_rest refuses. Amortised O(1).
  Index add(const Nodes& nodes, const PatchPositions<N>& X, const std::array<std::uint8_t, N - 3>& edges,
            const std::array<std::uint8_t, N - 3>& clamped, const PlateMaterial& m);
  [[nodiscard]] const PatchRest& rest(Index e) const { return rest_[e]; }

  [[nodiscard]] double element_energy(Index e, const Positions& x) const override { return patch_energy<N>(x, rest_[e]); }
  [[nodiscard]] Gradient element_gradient(Index e, const Positions& x) const override {
    return patch_gradient<N>(x, rest_[e]);
  }
  [[nodiscard]] double element_energy_gradient(Index e, const Positions& x, Gradient& g) const override {
    return patch_energy_gradient<N>(x, rest_[e], g);
  }
  [[nodiscard]] Hessian element_hessian(Index e, const Positions& x) const override { return patch_hessian<N>(x, rest_[e]); }
  /// Gauss-Newton, PSD by construction (patch_hessian_gauss_newton).
  [[nodiscard]] Hessian element_hessian_psd(Index e, const Positions& x) const override {
    return patch_hessian_gauss_newton<N>(x, rest_[e]);
  }
  /// The exact Hessians with each interior edge's angle derivatives computed once for the two
  /// patches of this term that share it (patch_hessian_shared): half the angle Hessians of a
  /// mesh whose triangles all have three neighbours. O(elements); the table of shared edges is
  /// rebuilt after a topology change (O(hinges log hinges)). Not thread-safe per instance.
  void for_each_hessian(const StateView& s, const std::function<void(Index, const Hessian&)>& visit) const override;

 private:
  // Hinge k of element e is slot shared_[e].of[k] of hinge_nodes_ (in that slot's node order,
  // or reversed); the slots' derivatives are computed at each for_each_hessian.
  struct HingeSlots {
    std::array<Index, 3> of{};
    std::array<bool, 3> reversed{};
  };
  void build_hinge_slots() const;

  std::vector<PatchRest> rest_;
  mutable std::vector<HingeSlots> shared_;
  mutable std::vector<std::array<Index, 4>> hinge_nodes_;
  mutable std::vector<HingeDerivatives> derivatives_;
  mutable std::uint64_t slots_topology_ = ~std::uint64_t{0};
};

extern template class PatchBending<4>;
extern template class PatchBending<5>;
extern template class PatchBending<6>;

/// The terms add_patch_bending made (nullptr where no triangle had that many interior edges),
/// and for each element, the triangle it bends: triangle_of[K - 1][e] for PatchBending<3 + K>.
struct PatchTerms {
  PatchBending<4>* one = nullptr;
  PatchBending<5>* two = nullptr;
  PatchBending<6>* three = nullptr;
  std::array<std::vector<Index>, 3> triangle_of;
};

/// Adds patch bending over a triangle list (node indices; rest positions read from rest_x, 3
/// per node; material per triangle, PlateMaterial::stiffness from plate_material). An edge shared
/// by exactly two triangles is interior; one triangle: a free boundary; three or more:
/// non-manifold, treated as free by each. `clamp_of_triangle` (empty: none) marks held
/// triangles (all their nodes fixed): they bend nothing themselves, and a neighbour's edge with
/// one is clamped (its slope held, patch_element.hpp). The two triangles of an interior edge must be
/// oriented consistently (else InputError naming them). Throws InputError naming the triangle
/// when its patch is refused; nothing is added to `sys` then. O(T log T).
PatchTerms add_patch_bending(System& sys, std::span<const std::array<Index, 3>> triangles, std::span<const double> rest_x,
                             std::span<const PlateMaterial> material_of_triangle,
                             std::span<const std::uint8_t> clamp_of_triangle = {});

}  // namespace sewn::physics::shells
