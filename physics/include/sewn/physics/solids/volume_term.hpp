#pragma once
// VolumePreservation: a volume energy per element in the manner of Teschner et al. 2004
// ("Robust real-time deformation of incompressible surface meshes"): each element resists a
// change of its volume with E = ½ κ w (J - 1)², J = V/V̄ its volume ratio, κ a bulk stiffness
// (Pa) and w the rest volume the stencil stands for. Springs see lengths, not orientation, so
// a region much softer than its load can be turned inside out without any spring resisting;
// this term makes that cost κ·w/2 per stencil at J = 0 and more beyond (J < 0).
//
// Stencils (4 nodes, a corner o and three neighbours a, b, c; J = det[a-o, b-o, c-o] over its
// rest value):
//   - a tetrahedron is one stencil, w = its rest volume;
//   - a hexahedron is its 8 corners (the same corners the inversion monitor checks), each with
//     w = V̄/8: an affine deformation gives every corner J = det F, so the 8 add up to the
//     element's ½ κ V̄ (det F - 1)², and a corner pushed through its element is resisted there.
// Forces = -gradient; ∂F/∂x = -Hessian, exact (κw[∇J∇Jᵀ + (J - 1)∇²J], indefinite away from
// J = 1) or PSD-projected when JacobianOptions::project_element_hessians is set.
// Cost: energy ~30 flops, gradient ~50, Hessian ~400 per stencil; a hexahedron is 8 stencils.

#include <array>
#include <cstdint>
#include <span>
#include <string_view>
#include <vector>

#include "sewn/physics/elements/stencil_term.hpp"

namespace sewn::physics {
template <int D>
class MssModel;
}  // namespace sewn::physics

namespace sewn::physics::solids {

using CornerPositions = Eigen::Matrix<double, 3, 4>;  // columns o, a, b, c

/// Rest data of one stencil: det of its rest edges and its weight κ·w (J).
struct VolumeStencil {
  double rest_det = 0.0;
  double stiffness = 0.0;  ///< κ·w
};

/// ½ s (J - 1)², its gradient (12) and exact Hessian (12×12) over a stencil's positions.
[[nodiscard]] double volume_energy(const CornerPositions& x, const VolumeStencil& r);
[[nodiscard]] elements::Vec<12> volume_gradient(const CornerPositions& x, const VolumeStencil& r);
[[nodiscard]] elements::Mat<12> volume_hessian(const CornerPositions& x, const VolumeStencil& r);

class VolumePreservation final : public elements::StencilTerm<4> {
 public:
  [[nodiscard]] std::string_view name() const override { return "volume"; }

  /// Adds a stencil on 4 distinct nodes with rest positions X (columns o, a, b, c), bulk
  /// stiffness kappa (Pa, > 0) standing for `weight` m³ of rest volume. Throws InputError (state
  /// unchanged) on a repeated node, a bad kappa or weight, or a flat rest stencil.
  Index add(const std::array<Index, 4>& nodes, const CornerPositions& X, double kappa, double weight);
  [[nodiscard]] const VolumeStencil& stencil(Index e) const { return rest_[e]; }

  /// Where stencil e's nodes come from: a model element and the local corners (VTK order) of
  /// its o, a, b, c. Set by add_volume_preservation; stencils added by hand have none.
  struct Source {
    Index element = invalid_index;
    std::array<std::uint8_t, 4> corners{};
  };
  void set_source(Index e, const Source& s) { source_[e] = s; }
  [[nodiscard]] const Source& source(Index e) const { return source_[e]; }
  /// Re-reads every sourced stencil's nodes from the model's element corners, as they are after
  /// an edit (a cut hands an element the copy of a duplicated particle), and retires the
  /// stencils of elements no longer alive (pierced away, or refined: the children stand for
  /// them). With per-material stiffnesses set (set_materials), every live hexahedron or
  /// tetrahedron whose material has one and that has no live stencil gets its stencils from its
  /// rest corners: refinement's children, and a parent coarsening revived (its old stencils
  /// stay retired). O(elements).
  void follow(const MssModel<3>& model);
  /// The bulk stiffness per model material that follow() gives new elements (0: none).
  void set_materials(std::vector<double> kappa_of_material) { kappa_of_material_ = std::move(kappa_of_material); }
  /// Adds the stencils of model element e (a hexahedron's 8 corners, each w = V̄/8, or a
  /// tetrahedron's one) at bulk stiffness kappa, sourced to e. Other kinds get none. O(1).
  void add_element(const MssModel<3>& model, Index e, double kappa);

  [[nodiscard]] double element_energy(Index e, const Positions& x) const override { return volume_energy(x, rest_[e]); }
  [[nodiscard]] Gradient element_gradient(Index e, const Positions& x) const override { return volume_gradient(x, rest_[e]); }
  [[nodiscard]] Hessian element_hessian(Index e, const Positions& x) const override { return volume_hessian(x, rest_[e]); }

 private:
  std::vector<VolumeStencil> rest_;
  std::vector<Source> source_;
  std::vector<double> kappa_of_material_;
};

/// Adds a VolumePreservation term over the live hexahedra and tetrahedra of `model`, each with
/// its material's bulk stiffness kappa_of_material[m] (0: that material gets none). Returns the
/// term, or nullptr when no element has a stiffness. Throws InputError on a negative or
/// non-finite stiffness (naming the material) or a size that does not match the materials.
/// The term follows the model's edits (MssModel::after_edits calls follow()): after a cut each
/// stencil uses its element's corner particles as they are then. O(elements).
VolumePreservation* add_volume_preservation(MssModel<3>& model, std::span<const double> kappa_of_material);

}  // namespace sewn::physics::solids
