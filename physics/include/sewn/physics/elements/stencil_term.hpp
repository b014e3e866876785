#pragma once
// StencilTerm<N>: the bookkeeping shared by force terms whose elements each couple a fixed
// set of N nodes through a potential energy (tetrahedra: 4, membrane triangles: 3, hinges:
// 4, patch bending: 4 to 6). A derived term supplies the element's energy, gradient and
// Hessian over its stencil (DOF order [x0 y0 z0 x1 ...]); this class turns them into the
// ForceTerm interface:
//   forces = -gradient, ∂F/∂x = -Hessian (its PSD stand-in element_hessian_psd per element
//   when JacobianOptions::project_element_hessians is set), no velocity dependence,
//   stability rows from the eigen-projected exact Hessian, pattern pairs, slot caching, node
//   checks and renumbering.
// Cost per pass: one element evaluation per element plus a scatter of 3N values (forces) or
// N² 3×3 blocks (Jacobians). Memory: N node indices and N² block slots per element.

#include <array>
#include <cstdint>
#include <functional>
#include <span>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "sewn/physics/elements/element_math.hpp"
#include "sewn/physics/force_term.hpp"

namespace sewn::physics::elements {

template <int N>
class StencilTerm : public ForceTerm {
 public:
  using Nodes = std::array<Index, N>;
  using Positions = Eigen::Matrix<double, 3, N>;
  using Gradient = Vec<3 * N>;
  using Hessian = Mat<3 * N>;

  /// Number of elements. O(1).
  [[nodiscard]] Index size() const { return static_cast<Index>(nodes_.size()); }
  /// The nodes of element e (no bounds check beyond the vector's).
  [[nodiscard]] const Nodes& element_nodes(Index e) const { return nodes_[e]; }
  /// Positions of element e's nodes in state s.
  [[nodiscard]] Positions gather(const StateView& s, Index e) const;
  /// Moves element e onto other nodes with the same rest data: a cut that duplicated a corner
  /// particle hands the element its copy. Throws InputError (naming the element, unchanged) if
  /// e is out of range or a node repeats. O(1); the Jacobian pattern is rebuilt when next needed.
  void set_element_nodes(Index e, const Nodes& nodes);
  /// Takes element e out of the term for good (the model element it stood for was removed):
  /// no energy, force or Jacobian, and its nodes may be removed. O(1).
  void retire_element(Index e);
  /// False once retire_element(e) was called.
  [[nodiscard]] bool is_alive(Index e) const { return alive_[e] != 0; }

  void add_forces(const StateView& s, std::span<double> f) const override;
  /// Element forces are gradients of an energy of the gathered positions.
  [[nodiscard]] bool velocity_dependent() const override { return false; }
  [[nodiscard]] double potential_energy(const StateView& s) const override;
  /// One gather and one element_energy_gradient per element.
  double add_forces_and_energy(const StateView& s, std::span<double> f) const override;
  void collect_pairs(std::vector<NodePair>& out) const override;
  void bind_pattern(const BlockMatrix& pattern) override;
  void add_jacobians(const StateView& s, const JacobianRequest& req) const override;
  void add_stability_rows(const StateView& s, StabilityRows& rows) const override;
  void check_nodes(const NodeTable& nodes) const override;
  void remap_nodes(std::span<const Index> old_to_new) override;

  /// Energy, gradient and exact Hessian of element e at positions x.
  [[nodiscard]] virtual double element_energy(Index e, const Positions& x) const = 0;
  [[nodiscard]] virtual Gradient element_gradient(Index e, const Positions& x) const = 0;
  [[nodiscard]] virtual Hessian element_hessian(Index e, const Positions& x) const = 0;
  /// Energy of element e at x, its gradient written to g: the same values as element_energy
  /// and element_gradient. Default: those two calls; a term whose energy and gradient share
  /// work (membranes: the strain; patch bending: the dihedral angles) overrides it.
  [[nodiscard]] virtual double element_energy_gradient(Index e, const Positions& x, Gradient& g) const {
    g = element_gradient(e, x);
    return element_energy(e, x);
  }
  /// A positive-semidefinite stand-in for the Hessian, used where Newton asks for projected
  /// element Hessians (the stability rows keep the eigen-projection of the exact one).
  /// Default: element_hessian with its negative eigenvalues clamped (project_psd, one
  /// eigendecomposition); a term with a cheaper closed form that is PSD by construction
  /// overrides it (and says how it differs from the exact one).
  [[nodiscard]] virtual Hessian element_hessian_psd(Index e, const Positions& x) const {
    Hessian H = element_hessian(e, x);
    project_psd(H);
    return H;
  }
  /// Every live element's exact Hessian at s, as visit(e, H) in element order: add_jacobians'
  /// loop. Default: element_hessian(e, gather(s, e)) per element; a term whose elements share
  /// work overrides it to do that work once (patch bending: the two patches of an edge share
  /// its angle's derivatives), with the same Hessians up to round-off.
  virtual void for_each_hessian(const StateView& s, const std::function<void(Index, const Hessian&)>& visit) const;

 protected:
  /// Appends an element; throws InputError (naming the term) if a node repeats. Returns its index.
  Index push_element(const Nodes& nodes);
  /// "tets element 12" and the like, for messages.
  [[nodiscard]] std::string element_name(Index e) const;

 private:
  void check_distinct(Index e, const Nodes& nodes) const;

  std::vector<Nodes> nodes_;
  std::vector<std::uint8_t> alive_;  // per element: 0 once retired
  std::vector<Index> slots_;  // N² per element, row-major (a, b)
  std::uint64_t bound_pattern_ = ~std::uint64_t{0};
  std::uint64_t bound_topology_ = ~std::uint64_t{0};
};

extern template class StencilTerm<3>;
extern template class StencilTerm<4>;
extern template class StencilTerm<5>;
extern template class StencilTerm<6>;

}  // namespace sewn::physics::elements
