#pragma once
// Tets: a force term of elastic linear tetrahedra (solids/tet_element.hpp) with a material
// and a rest shape per element, one law for the whole term (StVK or stable neo-Hookean).
// Energy Σ_e V̄_e Ψ(F_e); forces = -gradient; ∂F/∂x = -Hessian (exact, or, when
// JacobianOptions::project_element_hessians is set, tet_hessian_psd: PSD in closed form). No damping of its own (add
// MassDamping, or let NewtonEuler's incremental potential dissipate). A scene without solids
// does not instantiate it.
// Cost: forces ~0.2 µs per element, exact Jacobians ~2 µs per element; projected ones add a
// 3×3 SVD (neo-Hookean) or eigensolve (StVK) instead of a 12×12 eigendecomposition.

#include <array>
#include <string_view>
#include <vector>

#include "sewn/physics/elements/stencil_term.hpp"
#include "sewn/physics/solids/tet_element.hpp"

namespace sewn::physics::solids {

class Tets final : public elements::StencilTerm<4> {
 public:
  explicit Tets(TetLaw law = TetLaw::stvk) : law_(law) {}
  [[nodiscard]] std::string_view name() const override { return "tets"; }
  [[nodiscard]] TetLaw law() const { return law_; }

  /// Adds a tetrahedron on 4 distinct nodes with rest positions X (column i for nodes[i]) and
  /// Young's modulus / Poisson's ratio. Throws InputError (state unchanged) on a repeated node,
  /// a degenerate rest shape or a bad material. Returns the element index. Amortised O(1);
  /// the Jacobian pattern is rebuilt at the next assembly.
  Index add(const std::array<Index, 4>& nodes, const TetPositions& X, double young, double poisson);
  [[nodiscard]] const TetRest& rest(Index e) const { return rest_[e]; }
  [[nodiscard]] const Lame& material(Index e) const { return lame_[e]; }

  [[nodiscard]] double element_energy(Index e, const Positions& x) const override {
    return tet_energy(law_, x, rest_[e], lame_[e]);
  }
  [[nodiscard]] Gradient element_gradient(Index e, const Positions& x) const override {
    return tet_gradient(law_, x, rest_[e], lame_[e]);
  }
  [[nodiscard]] Hessian element_hessian(Index e, const Positions& x) const override {
    return tet_hessian(law_, x, rest_[e], lame_[e]);
  }
  /// Closed form, no 12×12 eigendecomposition (tet_hessian_psd).
  [[nodiscard]] Hessian element_hessian_psd(Index e, const Positions& x) const override {
    return tet_hessian_psd(law_, x, rest_[e], lame_[e]);
  }

 private:
  TetLaw law_;
  std::vector<TetRest> rest_;
  std::vector<Lame> lame_;
};

}  // namespace sewn::physics::solids
