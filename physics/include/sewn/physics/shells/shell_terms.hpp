#pragma once
// Force terms of thin shells, each paid for only by scenes that use it:
//   Membranes  CST membrane triangles (shells/membrane_element.hpp), material and thickness
//              per element;
//   Hinges     hinge bending over interior edges (shells/hinge_element.hpp), k_B per hinge.
// Forces = -gradient; ∂F/∂x = -Hessian (exact, or, when JacobianOptions::
// project_element_hessians is set, a PSD closed form per element: the membrane's with its
// compressive stresses clamped, the hinge's Gauss-Newton part); no damping of their own.
// Cost: membranes ~0.1 µs (forces) / ~1 µs (Jacobians) per triangle, hinges ~0.2 / ~3 µs.

#include <array>
#include <span>
#include <string_view>
#include <vector>

#include "sewn/physics/elements/stencil_term.hpp"
#include "sewn/physics/shells/hinge_element.hpp"
#include "sewn/physics/shells/membrane_element.hpp"

namespace sewn::physics::shells {

class Membranes final : public elements::StencilTerm<3> {
 public:
  [[nodiscard]] std::string_view name() const override { return "membranes"; }
  /// Adds a triangle on 3 distinct nodes with rest positions X (column i for nodes[i]).
  /// Throws InputError (unchanged) on a repeated node, a degenerate rest triangle or a bad
  /// material or thickness. Returns the element index. Amortised O(1).
  Index add(const std::array<Index, 3>& nodes, const TriPositions& X, double young, double poisson, double thickness);
  [[nodiscard]] const TriRest& rest(Index e) const { return rest_[e]; }

  [[nodiscard]] double element_energy(Index e, const Positions& x) const override {
    return membrane_energy(x, rest_[e], mat_[e]);
  }
  [[nodiscard]] Gradient element_gradient(Index e, const Positions& x) const override {
    return membrane_gradient(x, rest_[e], mat_[e]);
  }
  [[nodiscard]] double element_energy_gradient(Index e, const Positions& x, Gradient& g) const override {
    return membrane_energy_gradient(x, rest_[e], mat_[e], g);
  }
  [[nodiscard]] Hessian element_hessian(Index e, const Positions& x) const override {
    return membrane_hessian(x, rest_[e], mat_[e]);
  }
  /// Closed form, no eigendecomposition: compressive principal stresses clamped in the
  /// geometric term (membrane_hessian_psd).
  [[nodiscard]] Hessian element_hessian_psd(Index e, const Positions& x) const override {
    return membrane_hessian_psd(x, rest_[e], mat_[e]);
  }

 private:
  std::vector<TriRest> rest_;
  std::vector<MembraneMaterial> mat_;
};

class Hinges final : public elements::StencilTerm<4> {
 public:
  [[nodiscard]] std::string_view name() const override { return "hinges"; }
  /// Adds a hinge (node order and rest data: hinge_element.hpp) with bending stiffness k_b > 0
  /// (hinge_stiffness(E, ν, h) gives D/6). Throws InputError (unchanged) on a repeated node, a
  /// degenerate rest hinge or a k_b that is not finite and > 0. Amortised O(1).
  Index add(const std::array<Index, 4>& nodes, const HingePositions& X, double k_b);
  /// Adds one hinge per interior edge shared by exactly two of the triangles (node indices;
  /// rest positions read from rest_x, 3 per node), each with k_b. Edges with one triangle are
  /// boundary, with three or more non-manifold: neither gets a hinge. The two triangles must
  /// be oriented consistently across the edge (else InputError naming them), so that the rest
  /// angle is the fold, not the fold plus π. Returns the number of hinges added.
  /// O(T log T).
  Index add_interior_edges(std::span<const std::array<Index, 3>> triangles, std::span<const double> rest_x,
                           double k_b);
  /// The same with a stiffness per triangle: a hinge gets the mean of its two triangles' k_b
  /// (k_b_of_triangle.size() must equal triangles.size(), else InputError).
  Index add_interior_edges(std::span<const std::array<Index, 3>> triangles, std::span<const double> rest_x,
                           std::span<const double> k_b_of_triangle);
  [[nodiscard]] const HingeRest& rest(Index e) const { return rest_[e]; }
  [[nodiscard]] double stiffness(Index e) const { return k_[e]; }

  [[nodiscard]] double element_energy(Index e, const Positions& x) const override {
    return hinge_energy(x, rest_[e], k_[e]);
  }
  [[nodiscard]] Gradient element_gradient(Index e, const Positions& x) const override {
    return hinge_gradient(x, rest_[e], k_[e]);
  }
  [[nodiscard]] Hessian element_hessian(Index e, const Positions& x) const override {
    return hinge_hessian(x, rest_[e], k_[e]);
  }
  /// Gauss-Newton, PSD by construction (hinge_hessian_gauss_newton).
  [[nodiscard]] Hessian element_hessian_psd(Index e, const Positions& x) const override {
    return hinge_hessian_gauss_newton(x, rest_[e], k_[e]);
  }

 private:
  std::vector<HingeRest> rest_;
  std::vector<double> k_;
};

}  // namespace sewn::physics::shells
