#pragma once
// The force term of Morley bending (shells/morley_element.hpp): one element per triangle with
// at least one bending edge, and one angle DOF per edge in the System's angle table (inertia
// 0: the mid-normals are solved with the positions in every Newton step). Because of those
// angles only NewtonEuler steps a system that holds it (the other integrators refuse angles).
// Forces = -gradient (positions) and torques -∂E/∂ψ (angles); the Jacobian is -Hessian over
// positions and angles (PSD-projected per element when JacobianOptions::project_element_hessians).
// Cost per element: forces ~1 µs, Jacobian ~15 µs (two angle Hessians and a 21×21 projection).

#include <array>
#include <cstdint>
#include <span>
#include <string_view>
#include <vector>

#include "sewn/physics/force_term.hpp"
#include "sewn/physics/shells/morley_element.hpp"
#include "sewn/physics/system.hpp"

namespace sewn::physics::shells {

class MorleyBending final : public ForceTerm {
 public:
  struct Element {
    std::array<Index, 6> nodes{};  ///< corners, then the node across edge i (invalid_index if unused)
    std::array<Index, 3> angle{};  ///< System angle of edge i (invalid_index for a clamp)
    MorleyRest rest;
  };
  /// Adds an element (rest data from morley_rest). Throws InputError naming the element if a
  /// used slot repeats a node or an own/other edge has no angle. O(1).
  Index add(const Element& e);
  [[nodiscard]] Index size() const { return static_cast<Index>(elements_.size()); }
  [[nodiscard]] const Element& element(Index e) const { return elements_[e]; }

  [[nodiscard]] std::string_view name() const override { return "Morley bending"; }
  [[nodiscard]] bool velocity_dependent() const override { return false; }
  /// Throws InputError if the state carries fewer angles than the elements use.
  void add_forces(const StateView& s, std::span<double> f) const override;
  [[nodiscard]] double potential_energy(const StateView& s) const override;
  void collect_pairs(std::vector<NodePair>& out) const override;
  void bind_pattern(const BlockMatrix& pattern) override;
  void add_jacobians(const StateView& s, const JacobianRequest& req) const override;
  void check_nodes(const NodeTable& nodes) const override;
  void remap_nodes(std::span<const Index> old_to_new) override;

 private:
  // The element's block rows (6 node slots, 3 angle slots; invalid_index where unused) and the
  // component within its block of each of the 21 DOFs.
  void blocks(const Element& e, std::array<Index, 9>& block, std::array<int, 21>& comp) const;
  void gather(const StateView& s, const Element& e, MorleyPositions& x, Eigen::Vector3d& psi) const;

  std::vector<Element> elements_;
  std::vector<Index> slots_;  // 81 per element, (group a, group b) row-major; invalid where unused
  std::uint64_t bound_pattern_ = ~std::uint64_t{0};
};

/// What add_morley_bending made: the term (nullptr if no triangle bends), each element's
/// triangle, and the System angles of the edges (first_angle .. first_angle + angles - 1).
struct MorleyTerms {
  MorleyBending* term = nullptr;
  std::vector<Index> triangle_of;
  Index first_angle = 0;
  Index angles = 0;
};

/// Adds Morley bending over a triangle list (node indices, counter-clockwise consistently;
/// rest positions from rest_x, 3 per node; material per triangle from plate_material). An edge
/// of two triangles is interior (one angle, owned by the lower-numbered triangle); of one, a
/// free boundary (one angle); of three or more, non-manifold, each triangle then a free
/// boundary there with an angle of its own. `clamp_of_triangle` (empty: none) marks held
/// triangles (all their nodes fixed): they bend nothing, and an edge between one and a free
/// triangle is a clamp (no angle). Throws InputError naming the triangle when it is refused;
/// nothing is added to `sys` then. O(T log T).
MorleyTerms add_morley_bending(System& sys, std::span<const std::array<Index, 3>> triangles, std::span<const double> rest_x,
                               std::span<const PlateMaterial> material_of_triangle,
                               std::span<const std::uint8_t> clamp_of_triangle = {});

}  // namespace sewn::physics::shells
