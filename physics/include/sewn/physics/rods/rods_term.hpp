#pragma once
// Rods: discrete elastic rods as a ForceTerm on the system's node positions. Each rod's
// material angles θ are the term's own state, solved quasi-statically: whenever forces or the
// energy are asked for at a new state, θ is minimised with positions held (Rod::solve_twist,
// a Newton on the tridiagonal θ block from the previous θ). Because ∂E/∂θ = 0 there, the
// position gradient of E is the exact gradient of the reduced energy min_θ E (envelope
// theorem): the forces are exact.
//
// Jacobian. The exact ∂F/∂x of the reduced energy is −(H_xx − H_xθ H_θθ⁻¹ H_θx): the Schur
// complement over θ, which couples every vertex of a rod with every other (H_θθ⁻¹ is dense).
// add_jacobians() writes −H_xx only (stencil by stencil, each projected to PSD unless
// set_project_hessians(false)): stiffer than the exact reduced Jacobian (H_θθ is positive
// definite), so a linearly implicit step stays stable and is merely more damped in modes that
// couple bending and twist; for a straight rod H_xθ = 0 and nothing is dropped. The test
// suite builds the Schur complement from Rod::evaluate and checks it against finite differences.
//
// θ as degrees of freedom (use_angle_dofs): every edge's θ becomes an angle of the System
// (System::angles()), with inertia J = ρ·J_section·|ē| or none, integrated by the Newton
// integrator beside the positions. The term then reads θ from the state, writes the torques
// −∂E/∂θ after the position forces, and assembles each stencil's full 11×11 Hessian (positions
// and angles, projected to PSD when the request asks, JacobianOptions::project_element_hessians,
// and set_project_hessians has not turned projection off): the exact Jacobian, so Newton
// converges quadratically where the quasi-static mode's −H_xx does not. Connections
// (connect/) that hold a rod edge's frame need this mode: their θ gradient enters the same
// Newton system. set_quasi_static(false) alone leaves θ to a caller (Rod::set_theta).
//
// Condensed twist (condense_twist): θ quasi-static as above, with θ rows in the Newton system
// so that its position step is the reduced energy's exact Newton step (see the method).
//
// Time-parallel frames are updated in step_accepted(), which integrators call once per accepted
// step; within a step the frames are frozen (PHYSICS_NOTES §3.4's history state).

#include <array>
#include <span>
#include <string_view>
#include <vector>

#include "sewn/physics/force_term.hpp"
#include "sewn/physics/rods/rod.hpp"

namespace sewn::physics::rods {

class Rods final : public ForceTerm {
 public:
  /// Adds a rod through `nodes` (node indices in order; closed: the last joins the first) whose
  /// rest shape is their positions in x (3·N state array); see Rod's constructor for
  /// `rest_directors` and what is rejected. Throws InputError on a repeated or out-of-range
  /// node. Returns the rod's index. O(rod length); the pattern is rebuilt when next needed.
  Index add_rod(std::span<const Index> nodes, std::span<const double> x, bool closed, const Section& section,
                std::span<const Vec3> rest_directors = {});
  [[nodiscard]] Index num_rods() const { return static_cast<Index>(rods_.size()); }
  /// The rod (its θ, clamps, frames). Changing θ or clamps through it takes effect at the next
  /// force evaluation. The reference is invalidated by add_rod(). Throws InputError if r is
  /// out of range.
  [[nodiscard]] Rod& rod(Index r);
  [[nodiscard]] const Rod& rod(Index r) const;
  [[nodiscard]] std::span<const Index> rod_nodes(Index r) const;
  /// Positions of rod r's vertices in state array x (3N). O(rod length).
  [[nodiscard]] Points gather(Index r, std::span<const double> x) const;

  /// Quasi-static θ (default) or θ owned by the caller (see the header comment).
  void set_quasi_static(bool on) { quasi_static_ = on; }
  /// Makes every rod's θ angle DOFs of `angles` (a System's angles()): per rod, edge by edge,
  /// with the rod's current θ, inertia `inertia_per_length`·l̄ per edge (ρ times the section's
  /// polar moment, kg·m: ρπr⁴/2 for a circle; 0: no inertia — θ is solved with the positions
  /// in every Newton step) and each rod's fixed θ fixed. Ends the quasi-static solve. Rods
  /// added later are refused. Throws InputError if called twice or with a negative or
  /// non-finite inertia. O(edges).
  void use_angle_dofs(AngleTable& angles, double inertia_per_length);
  /// Keeps θ quasi-static but gives the Newton integrator the exact Jacobian of the reduced
  /// energy: every edge's θ becomes a condensed angle of `angles` (AngleTable::set_condensed:
  /// no inertia, in the linear system only) and add_jacobians assembles each stencil's 11×11
  /// Hessian at the solved θ over (x, θ), so the solve's position step is the Newton step of
  /// min_θ E (the Schur complement above, without forming it) while the term still solves θ at
  /// every evaluation: quadratic convergence on bent and twisted rods (a helical spring), where
  /// −H_xx alone converges linearly. After use_angle_dofs, the edges in `held` stay DOFs (the
  /// edges a connection turns: their θ is read from the state and held in the twist solve) and
  /// the others are condensed: min over those θ. A rod with no angle held or fixed that
  /// turns_freely() gets its first angle fixed in the table (its θ block is singular along
  /// (1, ..., 1), which H_xθ does not see). Only the Newton integrator accepts the system then.
  /// Throws InputError if called twice, with `held` before use_angle_dofs or out of range, or
  /// if θ is the caller's (set_quasi_static(false)). O(edges).
  struct RodEdge {
    Index rod = 0;
    int edge = 0;
  };
  void condense_twist(AngleTable& angles, std::span<const RodEdge> held = {});
  /// θ are System angle DOFs (use_angle_dofs; with a condensed twist, the held ones).
  [[nodiscard]] bool has_angle_dofs() const { return angle_dofs_; }
  /// The System angle that holds θ of rod r's edge j (use_angle_dofs). Throws InputError if out
  /// of range or the rods have no angle DOFs.
  [[nodiscard]] Index angle_of(Index r, int edge) const;
  /// Whether add_jacobians projects each stencil's position Hessian to PSD (default true).
  void set_project_hessians(bool on) { project_ = on; }

  /// What each rod carries from one step to the next (checkpoints): the rod's own state, and
  /// the positions θ was last solved at (3 per vertex; empty: none since θ last changed). With
  /// the latter a restored term solves θ again exactly when the running one would, so the
  /// quasi-static θ keeps its bits.
  struct RodHistory {
    Rod::State rod;
    std::vector<double> solved_at;
  };
  [[nodiscard]] std::vector<RodHistory> history() const;
  /// Takes up history() of a term built the same way. Throws InputError (nothing changed) if
  /// the number of rods, a rod's sizes or a value does not fit. O(vertices).
  void restore(std::span<const RodHistory> h);

  [[nodiscard]] std::string_view name() const override { return "rods"; }
  [[nodiscard]] bool velocity_dependent() const override { return false; }
  /// Solves θ at s (if s changed since the last solve), then adds −∂E/∂x. Throws
  /// rods::SolveError if a twist solve fails. O(vertices · twist Newton iterations).
  void add_forces(const StateView& s, std::span<double> f) const override;
  /// Energy at s, with θ solved there. Same cost as add_forces.
  [[nodiscard]] double potential_energy(const StateView& s) const override;
  /// Σ ½ EA l̄ over edges (the energy of a 100 % stretch).
  [[nodiscard]] double energy_scale() const override;
  void collect_pairs(std::vector<NodePair>& out) const override;
  void bind_pattern(const BlockMatrix& pattern) override;
  /// −H_xx as described above, at the θ of the last solve (with angles in the system: the
  /// stencils' full Hessians over positions and angles; their PSD stand-in is the bend–twist
  /// Gauss–Newton Hessian, Want::gauss_newton, 1.5 µs). O(stencils), a few µs each (AD
  /// Hessian, 2.4 µs measured, and a 9×9 eigen-decomposition).
  void add_jacobians(const StateView& s, const JacobianRequest& req) const override;
  void add_stability_rows(const StateView& s, StabilityRows& rows) const override;
  /// Transports every rod's reference frames to the accepted state and tracks its reference
  /// twists. O(vertices).
  void step_accepted(const StateView& s) override;
  void check_nodes(const NodeTable& nodes) const override;
  void remap_nodes(std::span<const Index> old_to_new) override;

 private:
  struct Entry {
    Rod rod;
    std::vector<Index> nodes;
    Points solved_at;             // positions of the last θ solve (0 columns: none yet)
    std::vector<Index> slots;     // per stencil 9 block slots (25 with angle DOFs), then per edge 4
    Index first_angle = invalid_index;  // with angle DOFs: θ^j is System angle first_angle + j
    std::vector<unsigned char> held;    // condensed twist: per edge, θ is a DOF held in the twist solve
    std::vector<double> start;          // θ every twist solve of the step starts from (empty: the current θ)
  };
  void ensure_twist(Index r, const Points& x) const;
  // Registers every rod's θ as angles of `angles` (first_angle), with the given inertia per length.
  void add_angles(AngleTable& angles, double inertia_per_length);
  // With angle DOFs: θ of rod r from the state (InputError if the state has no angles).
  void read_angles(Index r, const StateView& s) const;
  // Block rows of stencil s's 5 DOF groups (3 vertices, 2 edge angles) and the component of
  // each of its 11 DOFs.
  void stencil_blocks(const Entry& e, int s, std::array<Index, 5>& block, std::array<int, 11>& comp) const;
  void add_jacobians_with_angles(const StateView& s, const JacobianRequest& req) const;
  // Per-stencil and per-edge position Hessians of rod e at x (PSD-projected if `project`), calling
  // visit(vertex a, vertex b, 3×3 block, slot index into e.slots).
  template <class Visit>
  void for_each_block(const Entry& e, const Points& x, bool project, Visit&& visit) const;

  mutable std::vector<Entry> rods_;
  bool quasi_static_ = true;
  bool angle_blocks_ = false;  // θ rows in the Jacobian (use_angle_dofs or condense_twist)
  bool angle_dofs_ = false;    // use_angle_dofs was called
  bool project_ = true;
  std::uint64_t bound_pattern_ = ~std::uint64_t{0};
};

}  // namespace sewn::physics::rods
