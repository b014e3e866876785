#pragma once
// ForceTerm: the interface every force model implements (springs now; rods, shells, StVK
// tets, connections, contacts later), so that all of them share one node table, one
// sparsity pattern and one set of integrators. A term is a compact array of elements that
// refer to node indices; it
//   - adds its forces (its own damping included) at a given state,
//   - reports its potential energy,
//   - names the node pairs it couples (the sparsity pattern) and, once the pattern is built,
//     caches where its blocks live,
//   - adds a·∂F/∂x + b·∂F/∂v into that pattern, and optionally (∂F/∂x)·p,
//   - adds Gershgorin row sums of its stiffness and damping for the stable-step bound.
// A term that a scene does not instantiate costs nothing. Terms are not thread-safe: forces
// may use scratch buffers owned by the term.

#include <algorithm>
#include <array>
#include <cstdint>
#include <span>
#include <string_view>
#include <vector>

#include <Eigen/Core>

#include "sewn/physics/angles.hpp"
#include "sewn/physics/block_matrix.hpp"
#include "sewn/physics/types.hpp"

namespace sewn::physics {

class NodeTable;

/// How the Jacobian put into the solver matrix may differ from the exact one (PHYSICS_NOTES
/// §1.4). Forces are always exact.
struct JacobianOptions {
  /// Leave out position derivatives of velocity-dependent forces (for springs: ∂F^v/∂P, which
  /// is non-symmetric). Required by CG when a term uses per-spring viscosity.
  bool drop_viscous_position_terms = true;
  /// Replace (1 - l/d) by max(0, 1 - l/d) so that -∂F/∂x stays positive semidefinite.
  bool clamp_compression = true;
  /// Project each element Hessian to positive semidefinite (eigenvalues clamped at 0) before it
  /// enters the matrix, as Newton on an incremental potential needs (elements::StencilTerm).
  /// Springs need no projection of their own: their PSD form is clamp_compression.
  bool project_element_hessians = false;
};

/// One assembly pass: matrix += cx·∂F/∂x + cv·∂F/∂v (if matrix is set) and
/// product_out += (∂F/∂x)·product_in (if product_in is not empty), both with the same,
/// possibly simplified, ∂F/∂x.
struct JacobianRequest {
  BlockMatrix* matrix = nullptr;
  double cx = 0.0;
  double cv = 0.0;
  std::span<const double> product_in;
  std::span<double> product_out;
  JacobianOptions options;
};

/// Accumulates Gershgorin row sums of M^{-1/2} K M^{-1/2} and M^{-1/2} C M^{-1/2}, where K and
/// C are the positive-semidefinite stiffness and damping matrices (K = -∂F/∂x with compression
/// clamped, C = -∂F/∂v). Rows and columns of fixed axes are left out: the bound is for the
/// free system. Terms call add_diagonal / add_offdiagonal with their 3×3 blocks.
///
/// With slaves folded (`fold`, and `mass` the lumped masses of the reduced system), the rows are
/// those of the reduced system WᵀKW that the semi-implicit step integrates: a block on a slave
/// is passed to its masters with their weights (w_a w_b B), and the slaves' own rows are left
/// out (lumped mass 0). Off-diagonal parts are summed in absolute value as they arrive, which
/// can only raise a row: the bound stays an upper bound.
class SlaveExpansion;
class StabilityRows {
 public:
  enum Which { stiffness = 0, damping = 1 };
  struct Bound {
    double value = 0.0;          ///< upper bound on λmax(M^{-1}K) (or M^{-1}C), 1/s² (or 1/s)
    Index node = invalid_index;  ///< node whose row gives the bound
  };
  StabilityRows(std::span<const double> mass, std::span<const AxisMask> fixed, const SlaveExpansion* fold = nullptr);
  /// Block (i,i) of K or C receives +B; its symmetric part is kept (the bound is on the
  /// symmetric K and C whose spectra set the stable step).
  void add_diagonal(Which w, Index i, const Eigen::Matrix3d& B);
  /// Blocks (i,j) = B and (j,i) = Bᵀ (sign irrelevant: absolute values are summed).
  void add_offdiagonal(Which w, Index i, Index j, const Eigen::Matrix3d& B);
  /// A symmetric 3×3 block by its entries xx, yy, zz, xy, xz, yz.
  using SymBlock = std::array<double, 6>;
  /// A two-node term (a spring) whose stiffness and damping Hessians are [[B, -B], [-B, B]]
  /// for symmetric B = K and B = C: both diagonal blocks and the pair's off-diagonal block, in
  /// one call. The same rows as add_diagonal and add_offdiagonal would give; inline, with no
  /// 3×3 temporaries when neither node is a slave, since it runs once per spring.
  void add_pair(Index i, Index j, const SymBlock& K, const SymBlock& C) {
    if (fold_ != nullptr && (fold_is_slave(i) || fold_is_slave(j))) {
      add_pair_folded(i, j, K, C);
      return;
    }
    const double scale = inv_sqrt_mass_[i] * inv_sqrt_mass_[j];
    const double fi[3] = {free_[i], free_[stride_ + i], free_[2 * stride_ + i]};
    const double fj[3] = {free_[j], free_[stride_ + j], free_[2 * stride_ + j]};
    for (int w = 0; w < 2; ++w) {
      const SymBlock& B = w == stiffness ? K : C;
      double* d = diag_[w].data();
      for (int e = 0; e < 6; ++e) {
        d[e * stride_ + i] += B[e];
        d[e * stride_ + j] += B[e];
      }
      if (scale == 0) continue;  // a removed node: no row, no column
      const double a0 = std::abs(B[0]), a1 = std::abs(B[1]), a2 = std::abs(B[2]);
      const double a3 = std::abs(B[3]), a4 = std::abs(B[4]), a5 = std::abs(B[5]);
      double* o = off_[w].data();
      o[i] += scale * (fj[0] * a0 + fj[1] * a3 + fj[2] * a4);
      o[stride_ + i] += scale * (fj[0] * a3 + fj[1] * a1 + fj[2] * a5);
      o[2 * stride_ + i] += scale * (fj[0] * a4 + fj[1] * a5 + fj[2] * a2);
      o[j] += scale * (fi[0] * a0 + fi[1] * a3 + fi[2] * a4);
      o[stride_ + j] += scale * (fi[0] * a3 + fi[1] * a1 + fi[2] * a5);
      o[2 * stride_ + j] += scale * (fi[0] * a4 + fi[1] * a5 + fi[2] * a2);
    }
  }
  /// max over free axes of the scalar Gershgorin row sum. O(n).
  [[nodiscard]] Bound bound(Which w) const;
  /// The Gershgorin row sum of node i's `axis` row (0 for a fixed axis or a removed node).
  [[nodiscard]] double row(Which w, Index i, int axis) const;

  /// Entry (r, c) of a 3×3 block, at 3 c + r, -> its index in a SymBlock.
  static constexpr int sym_entry[9] = {0, 3, 4, 3, 1, 5, 4, 5, 2};
  /// The accumulators as per-entry arrays over the nodes, for a kernel that adds the rows of
  /// eight consecutive nodes at once (the springs' chunks, which pass no slave). Each array
  /// has room for eight values past the last node; what is added there is never read.
  struct Lanes {
    double* diag[2][6];         ///< diagonal blocks, entries in SymBlock order
    double* off[2][3];          ///< off-diagonal row sums, scaled by 1/sqrt(mi mj)
    const double* inv_sqrt_mass;  ///< 0 for a removed node
    const double* free[3];      ///< 1 for a free axis, 0 for a fixed one
  };
  /// True if the rows fold slaves onto their masters: then only add_pair and the block calls
  /// apply, never a lane kernel.
  [[nodiscard]] bool folds() const { return fold_ != nullptr; }
  [[nodiscard]] Lanes lanes();

 private:
  void diagonal_block(Which w, Index i, const Eigen::Matrix3d& B);
  void offdiagonal_block(Which w, Index i, Index j, const Eigen::Matrix3d& B);
  void add_pair_folded(Index i, Index j, const SymBlock& K, const SymBlock& C);
  [[nodiscard]] bool fold_is_slave(Index i) const;
  void axis_rows(Which w, int axis, std::size_t i0, std::size_t i1, double* out) const;
  [[nodiscard]] Bound bound_with_nan(Which w) const;
  std::span<const double> mass_;
  const SlaveExpansion* fold_ = nullptr;
  std::span<const AxisMask> fixed_;
  // Per-entry arrays over the nodes, each stride_ long (the node count, then eight spare).
  std::size_t stride_ = 0;
  std::vector<double> inv_sqrt_mass_;  // 1/sqrt(m), 0 for a removed node (no row, no column)
  std::vector<double> free_;           // 3 arrays: 1 for a free axis, 0 for a fixed one
  std::vector<double> diag_[2];        // 6 arrays: the diagonal blocks' entries, in SymBlock order
  std::vector<double> off_[2];         // 3 arrays: off-diagonal row sums, scaled by 1/sqrt(mi mj)
};

/// Whether a term's potential is internal (elastic) or due to an external field (gravity):
/// the energy watchdog counts work done by external fields as an energy income.
enum class EnergyKind { internal, external };

class ForceTerm {
 public:
  ForceTerm() = default;
  ForceTerm(const ForceTerm&) = default;
  ForceTerm& operator=(const ForceTerm&) = default;
  virtual ~ForceTerm() = default;

  /// Short name used in error messages ("springs", "gravity", ...).
  [[nodiscard]] virtual std::string_view name() const = 0;
  /// Adds this term's forces at state s into f (3n). Cost: one pass over the elements.
  virtual void add_forces(const StateView& s, std::span<double> f) const = 0;
  /// Sets f (3n) to this term's forces at state s. The default zeroes f and adds; a term that
  /// can write its forces directly overrides it and saves that pass (System::compute_forces
  /// calls it for its first term).
  virtual void set_forces(const StateView& s, std::span<double> f) const {
    std::fill(f.begin(), f.end(), 0.0);
    add_forces(s, f);
  }
  /// False if this term's forces depend on the positions and angles only, never on s.v or
  /// s.angle_rates. NewtonEuler evaluates only the velocity-dependent terms at a second
  /// velocity, and probes the ones without a dissipation potential (below). Default true: a term
  /// that does not say is evaluated at both velocities, which is always right, only slower.
  [[nodiscard]] virtual bool velocity_dependent() const { return true; }
  /// True if this term's velocity-dependent forces derive from dissipation() (below). NewtonEuler
  /// needs it of every term whose forces depend on velocity: backward Euler as an incremental
  /// potential has no other way to include a force that is not linear in v.
  [[nodiscard]] virtual bool dissipative() const { return false; }
  /// The dissipation potential Ψ(x, v) ≥ 0 at s, convex in v with Ψ(x, 0) = 0, whose velocity
  /// gradient is minus this term's velocity-dependent forces and whose velocity Hessian is minus
  /// their velocity Jacobian:
  ///     -∂Ψ/∂v = F(x, v) - F(x, 0)  (add_forces at s and at s with zero velocities),
  ///     -∂²Ψ/∂v² = ∂F/∂v           (the cv part of add_jacobians),
  /// with any history the forces read (friction's normal force) as they read it. So a term
  /// supplies only Ψ's value; its gradient and Hessian are the forces and Jacobians it already
  /// has. Linear damping F = -C(x) v has Ψ = ½ vᵀC(x)v; smoothed Coulomb friction
  /// μλ ε_v F1(|v_T|/ε_v). NewtonEuler adds h Ψ(x_n, v) to Φ, the positions lagged at the
  /// step's start (PHYSICS_NOTES §3.4). Cost: one pass over the elements.
  [[nodiscard]] virtual double dissipation(const StateView& /*s*/) const { return 0.0; }
  /// Potential energy at state s. Cost: one pass over the elements.
  [[nodiscard]] virtual double potential_energy(const StateView& s) const = 0;
  /// add_forces(s, f) and potential_energy(s) together, the energy returned: NewtonEuler's line
  /// search asks for both at each trial point, and a term whose elements compute them from
  /// shared intermediates (stencil terms: one gather, the strain or bending angles once)
  /// overrides this to make one pass instead of two. Default: the two calls.
  virtual double add_forces_and_energy(const StateView& s, std::span<double> f) const {
    const double e = potential_energy(s);
    add_forces(s, f);
    return e;
  }
  /// The largest fraction α ∈ (0, 1] of the change dq (laid out as a state: its x the 3n
  /// position changes, its angles the angle changes; velocities unused) that one Newton trial
  /// may take from the state s. For terms whose energy holds only for bounded changes within a
  /// trial (a connection's incremental twist aliases past π): NewtonEuler shortens each step,
  /// and its initial guess, to the smallest fraction the terms allow. Default 1: no limit.
  [[nodiscard]] virtual double step_fraction(const StateView& /*s*/, const StateView& /*dq*/) const { return 1.0; }
  [[nodiscard]] virtual EnergyKind energy_kind() const { return EnergyKind::internal; }
  /// A characteristic energy (springs: Σ ½ k l²) that sets the watchdog's noise floor.
  [[nodiscard]] virtual double energy_scale() const { return 0.0; }

  /// Appends the node pairs whose blocks this term writes (diagonal blocks always exist). A
  /// term with angle DOFs names their blocks through angle_layout().
  virtual void collect_pairs(std::vector<NodePair>& /*out*/) const {}
  /// Set by System before collect_pairs / bind_pattern: where the angle DOFs' blocks are.
  void set_angle_layout(AngleLayout layout) { angle_layout_ = layout; }
  /// Called after the pattern is (re)built: cache block slots. Cost: O(elements · log).
  virtual void bind_pattern(const BlockMatrix& /*pattern*/) {}
  /// Performs the request (see JacobianRequest). The matrix must carry the bound pattern.
  virtual void add_jacobians(const StateView& /*s*/, const JacobianRequest& /*req*/) const {}
  /// False if, with these options, the matrix contribution is not symmetric.
  [[nodiscard]] virtual bool jacobian_symmetric(const JacobianOptions& /*opt*/) const { return true; }
  /// Adds this term's stiffness and damping blocks for the stable-step bound.
  virtual void add_stability_rows(const StateView& /*s*/, StabilityRows& /*rows*/) const {}

  /// Called by integrators once per accepted step, at the new state: terms with history that
  /// is frozen within a step (rods' time-parallel frames, lagged contact normals) update it
  /// here. Default: nothing.
  virtual void step_accepted(const StateView& /*s*/) {}

  /// Throws InputError naming the element if one refers to a node out of range or removed.
  virtual void check_nodes(const NodeTable& /*nodes*/) const {}
  /// Renumbers nodes after compaction (old -> new, invalid_index for removed). check_nodes()
  /// has run before, so no element refers to a removed node.
  virtual void remap_nodes(std::span<const Index> /*old_to_new*/) {}

  /// Changes when elements are added, removed or re-attached (the pattern must be rebuilt).
  [[nodiscard]] std::uint64_t topology_version() const { return topology_version_; }
  /// Changes when a stiffness, rest length, damping coefficient or model changes.
  [[nodiscard]] std::uint64_t parameter_version() const { return parameter_version_; }

 protected:
  [[nodiscard]] const AngleLayout& angle_layout() const { return angle_layout_; }
  void touch_topology() {
    ++topology_version_;
    ++parameter_version_;
  }
  void touch_parameters() { ++parameter_version_; }

 private:
  AngleLayout angle_layout_;
  std::uint64_t topology_version_ = 0;
  std::uint64_t parameter_version_ = 0;
};

}  // namespace sewn::physics
