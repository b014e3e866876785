#pragma once
// Springs: the mass-spring term of PHYSICS_NOTES §1.4. Spring s joins nodes (i, j) with
// stiffness k, rest length l and (per-spring damping model) viscosity γ. With d = |Pj - Pi|,
// U = (Pj - Pi)/d, the force on i is
//   elastic   k (d - l) U
//   viscous   γ ((Vj - Vi)·U) U                       (SpringDamping::viscous)
//   Rayleigh  β K_s (Vj - Vi), K_s = k[UUᵀ + max(0, 1 - l/d)(I - UUᵀ)]   (::stiffness_proportional)
// and the force on j is its opposite. Jacobians are the exact ones of §1.4 (∂Fe/∂P,
// ∂Fv/∂P — non-symmetric — and ∂Fv/∂V; never the seed's W form), with the options of
// JacobianOptions. The Rayleigh matrix K_s is treated as constant within a step (its position
// derivative is not assembled), as is usual.
//
// Degenerate springs: below d = 1e-9·l (l > 0), or at d = 0, the direction is undefined; the
// spring then exerts no force and adds no Jacobian (PHYSICS_NOTES §1.4(c), "skip").
//
// Indices are stable: remove() leaves a tombstone (k = γ = 0, endpoints (0, 0)) whose slot is
// reused by the next add(); compact() renumbers and returns old -> new. The map's 1-attributes
// can therefore hold spring indices.

#include <cstdint>
#include <span>
#include <string_view>
#include <vector>

#include "sewn/physics/aligned.hpp"
#include "sewn/physics/force_term.hpp"
#include "sewn/physics/spring_runs.hpp"

namespace sewn::physics {

/// What a spring stands for, for callers that re-attach diagonals after a cut.
enum class SpringKind : std::uint8_t { edge, diagonal, other };

/// Damping model of the spring term (pick one; PHYSICS_NOTES §1.5).
enum class SpringDamping : std::uint8_t {
  none,
  viscous,                ///< the seed's per-spring γ((Vj-Vi)·U)U; γ is stored per spring
  stiffness_proportional  ///< Rayleigh's β·K_s part (add MassDamping(α) for the α·M part)
};

/// The seed's per-spring viscosity γ = 2 √(k (mi + mj)/2). Throws InputError on k < 0 or a
/// mass ≤ 0 or non-finite. O(1).
[[nodiscard]] double paper_viscosity(double k, double mi, double mj);

class Springs final : public ForceTerm {
 public:
  explicit Springs(SpringDamping damping = SpringDamping::none, double rayleigh_beta = 0.0);

  [[nodiscard]] std::string_view name() const override { return "springs"; }

  // ---- editing (all O(1) amortised; each throws InputError on bad input, naming the spring)
  /// Adds a spring between distinct nodes i and j (k ≥ 0, l ≥ 0, γ ≥ 0, all finite); returns
  /// its index (a freed slot if any). Node indices are checked against the node table when the
  /// system next steps. Bumps topology_version().
  Index add(Index i, Index j, double k, double rest_length, SpringKind kind = SpringKind::edge, double gamma = 0.0);
  /// Removes spring s (tombstone; its index may be reused). Bumps topology_version().
  void remove(Index s);
  void set_stiffness(Index s, double k);
  void set_rest_length(Index s, double l);
  void set_viscosity(Index s, double gamma);
  /// Re-attaches spring s to nodes (i, j). Bumps topology_version().
  void set_endpoints(Index s, Index i, Index j);
  /// Moves the end of spring s that is at node `from` to node `to` (a cut's re-attachment).
  /// Throws InputError if s does not end at `from`. Bumps topology_version().
  void move_endpoint(Index s, Index from, Index to);
  /// Sets γ of every live spring to paper_viscosity(k, mi, mj) from the given masses
  /// (call again after masses or stiffnesses change). O(springs).
  void set_paper_viscosity(std::span<const double> masses);
  /// Chooses the damping model (β is used by stiffness_proportional only, β ≥ 0).
  void set_damping(SpringDamping damping, double rayleigh_beta = 0.0);
  /// Reserves room for n springs.
  void reserve(Index n);
  /// Drops removed springs, keeping order; returns old -> new (invalid_index for removed). O(springs).
  std::vector<Index> compact();

  // ---- queries (O(1); throw InputError on a bad or removed index)
  [[nodiscard]] Index size() const { return static_cast<Index>(k_.size()); }  ///< slots, removed included
  [[nodiscard]] Index num_alive() const { return alive_count_; }
  [[nodiscard]] bool is_alive(Index s) const { return s < size() && alive_[s] != 0; }
  [[nodiscard]] Index node_i(Index s) const;
  [[nodiscard]] Index node_j(Index s) const;
  [[nodiscard]] double stiffness(Index s) const;
  [[nodiscard]] double rest_length(Index s) const;
  [[nodiscard]] double viscosity(Index s) const;
  [[nodiscard]] SpringKind kind(Index s) const;
  [[nodiscard]] SpringDamping damping() const { return damping_; }
  [[nodiscard]] double rayleigh_beta() const { return beta_; }
  /// Springs the force loop handled as chunks of runs in its last call (spring_runs.hpp); 0 if
  /// it used the row path for all of them. For tests and benchmarks. O(1).
  [[nodiscard]] Index num_in_runs() const { return runs_.worthwhile() ? runs_.num_chunked() : 0; }

  // ---- ForceTerm
  void add_forces(const StateView& s, std::span<double> f) const override;
  void set_forces(const StateView& s, std::span<double> f) const override;
  [[nodiscard]] double potential_energy(const StateView& s) const override;
  [[nodiscard]] bool dissipative() const override { return damping_ != SpringDamping::none; }
  /// Ψ = Σ ½ γ (ΔV·U)² (viscous) or Σ ½ β ΔVᵀK_sΔV (Rayleigh), degenerate springs left out as
  /// their forces are. O(springs).
  [[nodiscard]] double dissipation(const StateView& s) const override;
  [[nodiscard]] double energy_scale() const override;
  void collect_pairs(std::vector<NodePair>& out) const override;
  void bind_pattern(const BlockMatrix& pattern) override;
  void add_jacobians(const StateView& s, const JacobianRequest& req) const override;
  [[nodiscard]] bool jacobian_symmetric(const JacobianOptions& opt) const override;
  void add_stability_rows(const StateView& s, StabilityRows& rows) const override;
  void check_nodes(const NodeTable& nodes) const override;
  void remap_nodes(std::span<const Index> old_to_new) override;

 private:
  void check_spring(Index s, const char* where) const;
  // add_forces (accumulate) or set_forces (overwrite f).
  void forces(const StateView& s, std::span<double> f, bool accumulate) const;
  // The AoS path: every spring from rows of 4 doubles per node.
  void forces_by_rows(const StateView& s, std::span<double> f, bool accumulate) const;
  // The stable-step rows of the listed springs (dead ones skipped), one spring at a time.
  void stability_rows_of(std::span<const Index> springs, const StateView& s, StabilityRows& rows) const;
  [[nodiscard]] detail::SpringArrays arrays() const;
  // The assembly (spring_jacobian.cpp) runs in two phases: each spring's block and product
  // into per-spring arrays, then those added into the matrix and product_out.
  // Phase one over springs [s0, s1) (s0 a multiple of 8) for the symmetric Jacobians (every case but viscous damping
  // with its position terms kept): B = a·I + b·UUᵀ. Blocks are stored column-major, 9 a spring.
  void symmetric_blocks(const StateView& st, const JacobianRequest& req, Index s0, Index s1, double* blocks,
                        double* products, std::uint8_t* ok) const;
  // symmetric_blocks for springs [s, s + 8) in 512-bit vectors (AVX-512 builds).
  void symmetric_group(const StateView& st, const JacobianRequest& req, Index s, double* blocks, double* products,
                       std::uint8_t* ok) const;
  // Phase one for the general (non-symmetric) Jacobian.
  void general_blocks(const StateView& st, const JacobianRequest& req, Index s0, Index s1, double* blocks,
                      double* products, std::uint8_t* ok) const;
  bool spring_jacobian(const StateView& st, const JacobianRequest& req, Index s, Eigen::Matrix3d& Jx, Eigen::Matrix3d& B) const;
  [[nodiscard]] Eigen::Vector3d spring_product(const JacobianRequest& req, Index s, const Eigen::Matrix3d& Jx) const;
  // Phase two on one thread: chunk by chunk of springs, each block added spring by spring.
  template <bool Symmetric>
  void add_jacobians_serial(const StateView& st, const JacobianRequest& req) const;
  // Both phases on `parts` threads (one for a large model): the same result as the chunked
  // one-thread assembly, bitwise.
  template <bool Symmetric>
  void add_jacobians_threads(const StateView& st, const JacobianRequest& req, int parts) const;
  void build_incidence(Index nodes) const;
  // Springs per thread below which add_jacobians uses fewer threads.
  static constexpr Index jacobian_grain = 4096;
  // Springs from which one thread also assembles in the two phases of add_jacobians_threads
  // (measured on grids: 0.65-0.75x the chunked scatter's time at 32³, 0.9x at 21³, 16³ about
  // even, slower at 8³).
  static constexpr Index jacobian_gather_min = 16384;
  // Springs per chunk of the one-thread assembly (its buffers stay in the L1 cache).
  static constexpr Index jacobian_chunk = 128;

  // Structure of arrays: the force loop streams these in order.
  AlignedVector<Index> ni_, nj_;
  AlignedVector<double> k_, l_, gamma_;
  std::vector<SpringKind> kind_;
  std::vector<std::uint8_t> alive_;
  std::vector<Index> free_;
  Index alive_count_ = 0;
  Index max_node_ = 0;  // largest endpoint ever stored (the force loop's bounds check)
  SpringDamping damping_;
  double beta_;
  // Slots of blocks (i,j), (j,i), (i,i), (j,j) in the bound pattern.
  std::vector<Index> slot_ij_, slot_ji_, slot_ii_, slot_jj_;
  std::uint64_t bound_pattern_ = 0;
  std::uint64_t bound_topology_ = ~std::uint64_t{0};
  // Positions, velocities and the force accumulator as rows of 4 doubles per node, so each
  // spring end is one aligned 256-bit access (see springs.cpp). acc_ is zero between calls.
  mutable AlignedVector<double> x_rows_, v_rows_, acc_;
  // The chunked path for springs numbered in runs (spring_runs.hpp), used when most are.
  mutable detail::SpringRuns runs_;
  // The threaded assembly: each node's springs (2s + 0 at its i end, 2s + 1 at its j end, in
  // spring order), built per topology, and per-spring blocks, products and "has a direction".
  mutable std::vector<Index> incidence_row_, incidence_;
  mutable std::uint64_t incidence_topology_ = ~std::uint64_t{0};
  mutable AlignedVector<double> jac_blocks_, jac_products_;
  mutable std::vector<std::uint8_t> jac_ok_;
};

}  // namespace sewn::physics
