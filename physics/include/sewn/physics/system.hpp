#pragma once
// System: one node table plus the force terms acting on it, the shared block-sparsity
// pattern of their Jacobians, energies and the stable-step estimate. Integrators step a
// System; the map-based builders fill one.

#include <cstdint>
#include <memory>
#include <span>
#include <type_traits>
#include <utility>
#include <vector>

#include "sewn/physics/angles.hpp"
#include "sewn/physics/block_matrix.hpp"
#include "sewn/physics/constraints/slave_nodes.hpp"
#include "sewn/physics/force_term.hpp"
#include "sewn/physics/nodes.hpp"

namespace sewn::physics {

/// Estimate of the largest stable semi-implicit (symplectic Euler) step at the current state.
///
/// What it guarantees: with K the clamped stiffness (-∂F/∂x, compression clamped, so PSD) and
/// C the damping (-∂F/∂v) at this state, λ_K ≥ λmax(M⁻¹K) and λ_C ≥ λmax(M⁻¹C) are scalar
/// Gershgorin bounds over the free axes, and h_max solves h²λ_K + 2hλ_C = 4. For any h < h_max,
/// M - h²K/4 - hC/2 is positive definite, which makes the modified energy
/// ½δᵀ(M - h²K/4 - hC/2)δ/h² + ⅛(x₁+x₀)ᵀK(x₁+x₀) (δ = x₁ - x₀) non-increasing: the semi-implicit
/// Euler iteration of the system linearised at this state is stable, whatever the damping
/// (proportional or not). It is an upper bound on ω only, so h_max is conservative (the
/// Baudet grid's true limit is ~1.3× higher undamped). Not covered: the non-symmetric
/// ∂F^v/∂P, and stiffening once the state moves far from where the bound was taken.
/// With slave nodes under the reduction (T-junctions), M, K and C are the reduced system's that
/// the step integrates: lumped masses, WᵀKW and WᵀCW; no slave's row sets the bound.
struct StableStep {
  double h_max = 0.0;                  ///< +inf when nothing bounds the step
  double stiffness_bound = 0.0;        ///< λ_K, 1/s² (ω_max ≤ √λ_K)
  double damping_bound = 0.0;          ///< λ_C, 1/s
  Index stiffness_node = invalid_index;  ///< node whose Gershgorin row gives λ_K
  Index damping_node = invalid_index;    ///< node whose row gives λ_C
};

class System {
 public:
  System() = default;
  System(const System&) = delete;
  System& operator=(const System&) = delete;
  System(System&&) noexcept = default;
  System& operator=(System&&) noexcept = default;
  ~System() = default;

  [[nodiscard]] NodeTable& nodes() { return nodes_; }
  [[nodiscard]] const NodeTable& nodes() const { return nodes_; }
  /// Angle DOFs beyond positions (rods' twist angles when integrated); empty by default, and
  /// then nothing of them costs anything.
  [[nodiscard]] AngleTable& angles() { return angles_; }
  [[nodiscard]] const AngleTable& angles() const { return angles_; }
  /// The current state: the node table's view plus the angles. O(1).
  [[nodiscard]] StateView state() const;
  /// Throws InputError naming `integrator` if the system has angle DOFs (only NewtonEuler
  /// integrates them). O(1).
  void require_no_angles(const char* integrator) const;

  /// Constructs a term of type T in place and returns it (the reference stays valid for the
  /// System's lifetime). The pattern is rebuilt when next needed. O(1).
  template <class T, class... Args>
  T& add(Args&&... args) {
    static_assert(std::is_base_of_v<ForceTerm, T>);
    auto t = std::make_unique<T>(std::forward<Args>(args)...);
    T& ref = *t;
    terms_.push_back(std::move(t));
    return ref;
  }
  /// Takes ownership of a term; returns it.
  ForceTerm& add_term(std::unique_ptr<ForceTerm> term);
  [[nodiscard]] std::span<const std::unique_ptr<ForceTerm>> terms() const { return terms_; }

  /// Makes the system consistent after edits: when nodes or any term changed topology, checks
  /// every element's node references (InputError naming it) and marks the Jacobian pattern
  /// stale. Returns true if the topology changed. O(terms) when nothing changed, else O(elements).
  bool refresh();
  /// A value that changes whenever nodes or any term change topology (what refresh() watches),
  /// and only then. O(terms).
  [[nodiscard]] std::uint64_t topology_key() const;
  /// The Jacobian pattern and value storage, (re)built first if the topology changed: only
  /// integrators that assemble Jacobians pay for it. Block rows: the nodes, then the angles'
  /// (AngleLayout). O(elements·log) after a change, else O(terms).
  [[nodiscard]] BlockMatrix& matrix();
  [[nodiscard]] const BlockMatrix& matrix() const { return matrix_; }

  /// Sets the nodes' force array to the sum of all terms at the current state. Calls
  /// refresh(). O(elements).
  void compute_forces();
  /// Adds the forces of all terms at state s into f (3n, not zeroed). No refresh.
  void add_forces(const StateView& s, std::span<double> f) const;
  /// Performs req for every term (see JacobianRequest); the matrix is not zeroed first and no
  /// mass is added. Calls refresh(). O(elements).
  void add_jacobians(const JacobianRequest& req);

  /// Tells every term that a step was accepted at the current state (ForceTerm::step_accepted).
  /// Integrators call it once per step. O(terms) plus what the terms with history do.
  void step_accepted();

  /// ½ Σ m v² + ½ Σ J ω² over the angles. O(n).
  [[nodiscard]] double kinetic_energy() const;
  /// Σ of the terms' potentials. O(elements).
  [[nodiscard]] double potential_energy() const;
  /// Σ of the potentials of terms of one kind (internal = elastic, external = fields).
  [[nodiscard]] double potential_energy(EnergyKind kind) const;
  /// Σ of the terms' energy scales (see ForceTerm::energy_scale).
  [[nodiscard]] double energy_scale() const;

  /// Stable semi-implicit step at the current state (see StableStep). Calls refresh().
  /// Cost: about two force evaluations.
  [[nodiscard]] StableStep stable_step();

  /// Drops removed nodes and renumbers every term. Throws InputError (before changing
  /// anything) if an element still refers to a removed node. Returns old -> new node index.
  /// Invalidates node indices held by the caller (the map's 0-attributes must be remapped). O(n + elements).
  std::vector<Index> compact_nodes();

  /// Particles tied to others (T-junctions of refinement), which both integrators honour;
  /// empty by default. compact_nodes() renumbers them.
  [[nodiscard]] SlaveNodes& slaves() { return slaves_; }
  [[nodiscard]] const SlaveNodes& slaves() const { return slaves_; }

  /// Changes whenever a node or term parameter or topology changes, or a term is added
  /// (integrators cache the stable step and the energy baseline against it). It is a sum of
  /// counters that only increase, so any change increases it. O(terms).
  [[nodiscard]] std::uint64_t version() const;

 private:
  NodeTable nodes_;
  AngleTable angles_;
  std::vector<std::unique_ptr<ForceTerm>> terms_;
  BlockMatrix matrix_;
  SlaveNodes slaves_;
  std::uint64_t seen_topology_ = ~std::uint64_t{0};    // topology last checked by refresh()
  std::uint64_t pattern_topology_ = ~std::uint64_t{0};  // topology the matrix pattern was built for
};

}  // namespace sewn::physics
