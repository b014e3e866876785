#pragma once
// Slave nodes: particles whose position is tied to others, x_v = Σ_k w_k x_{c_k} (Σ w = 1), as
// the T-junctions of hierarchical refinement are (PHYSICS_NOTES §2.6). The integrators treat them
// by the virtual-work reduction: forces passed to the masters (f_c += w f_v), the slave's mass
// lumped onto them (the row sums of WᵀMW) in the semi-implicit step, the linear solve of the
// linearly implicit step done on the reduced system WᵀAW, and the slaves' positions and
// velocities interpolated after each step. Σ w = 1 and Σ w x_c = x_v keep total force, torque
// and momentum: a free body with slaves keeps its linear and angular momentum.
//
// The 2014 paper's treatment is kept as an option for comparison: the slave's force split in
// equal shares among the particles of the elements it is a corner of, the slave integrated as a
// free particle, then projected orthogonally onto the line of its 2 masters (or the plane of its
// 4); velocities untouched. It conserves total force but neither torque nor momentum.

#include <array>
#include <cstdint>
#include <span>
#include <utility>
#include <vector>

#include "sewn/physics/block_matrix.hpp"
#include "sewn/physics/cg.hpp"
#include "sewn/physics/nodes.hpp"

namespace sewn::physics {

struct SlaveNode {
  Index node = invalid_index;
  std::array<Index, 4> master{invalid_index, invalid_index, invalid_index, invalid_index};
  std::array<double, 4> weight{};
  int masters = 0;  ///< 2 (on an edge) or 4 (inside a face)
};

enum class SlaveTreatment : std::uint8_t {
  reduction,         ///< virtual-work reduction (conserves momentum)
  paper_projection,  ///< the 2014 paper: equal force shares, then orthogonal projection
};

/// The rows of W for the slaves: each slave written in particles that are not slaves,
/// x_v = Σ w_c x_c, nesting resolved (a slave master replaced by its own masters) and repeated
/// masters merged. What the stable-step bound folds slave rows with (StabilityRows).
class SlaveExpansion {
 public:
  struct Term {
    Index node = invalid_index;
    double weight = 0.0;
  };
  [[nodiscard]] bool is_slave(Index node) const { return node < slot_.size() && slot_[node] >= 0; }
  /// A slave's terms (weights summing to 1); call only when is_slave(node). O(1).
  [[nodiscard]] std::span<const Term> of(Index node) const {
    const auto k = static_cast<std::size_t>(slot_[node]);
    return std::span<const Term>(terms_).subspan(first_[k], first_[k + 1] - first_[k]);
  }

 private:
  friend class SlaveNodes;
  std::vector<std::int32_t> slot_;   // node -> slave's position in the list, -1 for others
  std::vector<std::size_t> first_;   // per slave, where its terms start (one past the end last)
  std::vector<Term> terms_;
};

class SlaveNodes {
 public:
  /// Replaces the set. Slaves must come coarse to fine: a master that is itself a slave is
  /// listed before the slaves it masters. `shares[i]` lists, for slave i, the particles and
  /// fractions its force goes to under the paper's treatment (may be empty otherwise). Throws
  /// InputError naming the slave for a weight sum ≠ 1, a master listed after its slave, or a
  /// slave listed twice. O(slaves).
  void set(std::vector<SlaveNode> slaves, std::vector<std::vector<std::pair<Index, double>>> shares = {});
  void clear() {
    const std::uint64_t r = revision_;
    *this = SlaveNodes{};
    revision_ = r + 1;
  }
  void set_treatment(SlaveTreatment t) {
    treatment_ = t;
    ++revision_;
  }
  [[nodiscard]] SlaveTreatment treatment() const { return treatment_; }
  [[nodiscard]] bool empty() const { return slaves_.empty(); }
  [[nodiscard]] std::span<const SlaveNode> slaves() const { return slaves_; }
  [[nodiscard]] bool reduces() const { return !empty() && treatment_ == SlaveTreatment::reduction; }

  /// Before integrating (forces computed, 3 per node): reduction: f_c += w f_v from fine to
  /// coarse, then f_v = 0; paper: f_v shared out, f_v = 0. O(slaves).
  void pass_forces(std::span<double> f) const;
  /// Inverse masses per axis for the semi-implicit step: reduction: the masters' lumped masses
  /// m_c + Σ w m_v (fine to coarse), 0 on slaves; paper: the nodes' own. O(n) when the slaves
  /// or the nodes' masses, fixed axes or numbering changed since the last call, else O(1)
  /// (kept: they change with the topology, not with the state).
  [[nodiscard]] std::span<const double> inverse_mass_dof(const NodeTable& nodes);
  /// The reduced system's lumped masses (row sums of WᵀMW): each master's own mass plus Σ w m_v
  /// of its slaves (fine to coarse, so nested slaves reach the particles that move), 0 on
  /// slaves; under the paper's treatment the nodes' own masses. O(n).
  [[nodiscard]] std::vector<double> lumped_masses(const NodeTable& nodes) const;
  /// W's slave rows over `nodes` particles (see SlaveExpansion). O(slaves · masters).
  [[nodiscard]] SlaveExpansion expansion(Index nodes) const;
  /// After a step: reduction: x_v and v_v interpolated coarse to fine; paper: x_v projected. O(slaves).
  void after_step(NodeTable& nodes) const;
  /// y ← Wᵀ y in place (3 per node): y_c += w y_v fine to coarse, y_v = 0. O(slaves).
  void reduce(std::span<double> y) const;
  /// z ← W z in place: z_v = Σ w z_c coarse to fine. O(slaves).
  void expand(std::span<double> z) const;
  /// Renumbers after System::compact_nodes() (old -> new; a removed slave or master drops the slave).
  void remap(std::span<const Index> old_to_new);

  /// The block-Jacobi preconditioner of the reduced system: the inverses (9 per node, as
  /// block_jacobi_inverse) of the diagonal blocks of Wᵀ D W, D the block diagonal of A: each
  /// master's own block plus w² times each of its slaves' (passed fine to coarse, so a nested
  /// slave's share reaches the particles that move; exact when each slave reaches a master by
  /// one path). Without the slaves' shares a master of many T-junctions is preconditioned by a
  /// block far lighter than its row of WᵀAW. O(n + slaves).
  void reduced_block_jacobi(const BlockMatrix& A, std::span<const double> free_dof, std::span<double> inverse);

  /// Solves (Wᵀ A W) z = Wᵀ b on the free master axes (free_dof 0 on fixed axes), by block-Jacobi
  /// PCG (precond_inverse: from reduced_block_jacobi), and returns x = W z; x holds the warm start
  /// on entry. O(iterations · blocks).
  CgResult solve_reduced(const BlockMatrix& A, std::span<const double> b, std::span<double> x,
                         std::span<const double> free_dof, std::span<const double> precond_inverse, double tolerance,
                         int max_iterations);

 private:
  std::vector<SlaveNode> slaves_;
  std::vector<std::vector<std::pair<Index, double>>> shares_;
  SlaveTreatment treatment_ = SlaveTreatment::reduction;
  void lump(const NodeTable& nodes, std::vector<double>& lumped) const;  // lumped_masses into a buffer

  // What inv_mass_ was made from: the nodes (which table, its versions) and the slaves (revision_,
  // bumped by every change of the set or the treatment).
  struct MassKey {
    const NodeTable* nodes = nullptr;
    std::uint64_t topology = 0, parameters = 0, slaves = 0;
    bool operator==(const MassKey&) const = default;
  };
  std::uint64_t revision_ = 0;
  MassKey inv_mass_key_;
  std::vector<double> inv_mass_, lumped_, r_, z_, p_, q_, ap_, free_, blocks_;
  CgWorkspace ws_;  // solve_reduced's packed path
};

}  // namespace sewn::physics
