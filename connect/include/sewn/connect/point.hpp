#pragma once
// Point connections (the 2019 paper's §4; PHYSICS_NOTES §3.5): the rotational energies that
// join two bodies meeting at one shared node. A conforming mesh already couples the positions;
// a point connection adds a twisting energy about the joint's axis and a bending energy of the
// axis, each between one frame per side:
//   E = ½ k_t (δ − δ̄)² + ½ k_b ω²,
//   δ = signed angle from P_{m3}^{n3}(m1) to n1 about n3 (tracked incrementally, see TwistUpdate),
//   ω = atan2(|d×d̄|, d·d̄), d = (n3·m1, n3·m2, n3·m3), d̄ its rest value.
//
// Sides and their frames (m = first side, n = second side, same construction):
//   RodEdgeSide  — the rod's material frame of one edge (physics/rods conventions: reference
//                  director transported from the stored tangent t̄, director ā1 to the current
//                  tangent, turned by θ): m1 = material m1, m3 = ±t, m2 = m3×m1.
//   TriangleSide — a shell triangle at its corner: m3 = ±hat(c1 e1 + c2 e2), e1, e2 the edges
//                  from the joint corner, (c1, c2) fixed at rest (the rest axis, by default the
//                  bisector of the corner's angle); m1 = the triangle's unit normal; m2 = m3×m1.
// Orientation rule: the first side's axis points into the joint, the second's out of it (a
// straight rod–rod continuation then has m̄3·n̄3 = 1); the second axis is flipped if still
// m̄3·n̄3 < 0. The twist is then measured from m's frame turned by a constant rotation (fixed
// at rest, in m's own coordinates) that carries m̄3 onto n̄3: δ = signed angle from
// P_{m'3}^{n3}(m'1) to n1 about n3, with m'3 = d1 m1 + d2 m2 + d3 m3 at d = d̄, so
// 1 + m'3·n3 = 1 + cos ω: the transport's singularity is the bend ω = π from the rest shape,
// however bent the joint is at rest (a spring's foot at 62° to the platform's normal would
// otherwise meet it after a bend of 118°). A straight joint's turn is the identity.
//
// Stencil DOF order q: the first side's DOFs, then the second's.
//   rod edge:  x_from (3), x_to (3), θ (1)   — 7; from/to in the rod's own edge direction
//   triangle:  x_joint (3), x_next (3), x_prev (3) — 9; the triangle's nodes rotated so that
//              the joint comes first (orientation, hence the normal's sign, is kept)
//   tet:       x_joint, then the other three in their order (12); F does not depend on the order
//   vertex:    x_joint, then the one-ring in its order (3 (ring + 1))
// The shared node thus has one 3-block per side; an assembler adds both. position_nodes()
// lists the node of every 3-block in order.

#include <array>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <variant>
#include <vector>

#include <Eigen/Core>

#include "sewn/physics/errors.hpp"
#include "sewn/physics/rods/rod.hpp"
#include "sewn/physics/types.hpp"

namespace sewn::connect {

using Vec3 = Eigen::Vector3d;
using physics::Index;

/// One rod edge as a side: its nodes in the rod's edge direction (from → to) and the rod's
/// reference frame history for that edge (the tangent t̄ and director ā1 at the rod's last
/// frame update). Build it from a Rod with rod_edge_side() so both stay in step.
struct RodEdgeSide {
  Index from = 0, to = 0;
  Vec3 tangent{1, 0, 0}, director{0, 1, 0};
};

/// Side for edge `edge` of `rod` at its current positions x (3×n), with the rod's reference
/// director there; node ids are the rod's vertex ids plus `node_offset`. O(1).
[[nodiscard]] RodEdgeSide rod_edge_side(const physics::rods::Rod& rod, const physics::rods::Points& x, int edge,
                                        Index node_offset = 0);

/// One shell triangle as a side (nodes in the shell's orientation). `rest_axis`: the axis m̄3
/// at rest, in the triangle's plane and inside the joint corner's angle (for a boundary vertex
/// with several incident triangles, the bisector of the whole fan lying in this triangle);
/// none: the bisector of this triangle's corner.
struct TriangleSide {
  std::array<Index, 3> nodes{};
  std::optional<Vec3> rest_axis;
};

/// A solid's tetrahedron as a side (PHYSICS_NOTES §3.5, solid option i): the rest frame — m̄3 =
/// `rest_axis` (the surface vertex normal at the joint, pointing out of the solid; the tet is
/// the one the inward normal ray enters), m̄1 any unit vector ⟂ to it — carried by the tet's
/// deformation gradient F and re-orthonormalised, m3 first: m3 = ±hat(F m̄3),
/// m1 = hat(F m̄1 − (F m̄1·m3) m3). The joint is one of its nodes.
struct TetSide {
  std::array<Index, 4> nodes{};
  Vec3 rest_axis{0, 0, 1};
};

/// A shell's interior vertex as a side (PHYSICS_NOTES §3.5): the joint and its one-ring, the
/// neighbours in order around it so that the triangles (joint, ring[i], ring[i+1]) (the last
/// closing on ring[0]) are the shell's. m3 = ±hat(Σ αi ni), the angle-weighted vertex normal
/// (αi the triangle's angle at the joint, ni its unit normal); m1 = hat(e − (e·m3) m3), e the
/// edge to ring[0]. Unlike a corner's bisector, the normal stands off the surface, so a rod
/// leaving the shell along it meets the transport's singularity only when folded back onto it.
struct VertexSide {
  Index joint = 0;
  std::vector<Index> ring;
};

using Side = std::variant<RodEdgeSide, TriangleSide, TetSide, VertexSide>;

/// How δ is followed through a motion (PHYSICS_NOTES §3.5). The incremental updates freeze
/// their history within a step and are advanced by accept(); both need each step's increment
/// to stay below π.
enum class TwistUpdate {
  direct,          ///< δ ∈ (−π, π]: wraps (kept to show why the others exist)
  incremental_i,   ///< the direct value + 2πk, closest to the last accepted δ
  incremental_ii,  ///< last δ + the signed angle left after turning m1 by it about m3
};

/// What one connection carries from one step to the next (checkpoints), flat: the accepted
/// twist, then per side (m, n) a rod side's frame history — tangent t̄ (3) and director ā1 (3),
/// zeros for other sides.
inline constexpr int history_size = 13;
using ConnectionHistory = std::array<double, history_size>;

/// Stiffnesses of one connection, per point and independent of resolution: k_t, k_b in N·m/rad.
struct PointStiffness {
  double twist = 0, bend = 0;
};

/// Values at one configuration. `gradient` is dE/dq in the stencil order (empty if not asked).
struct PointEval {
  double energy = 0;
  double twist = 0;       ///< δ by the update asked for
  double twist_raw = 0;   ///< the direct δ ∈ (−π, π]
  double bend_angle = 0;  ///< ω ∈ [0, π]
  bool near_antiparallel = false;  ///< 1 + m'3·n3 = 1 + cos ω < antiparallel_margin: transport near its singularity
  bool bend_near_pi = false;       ///< ω > π − bend_margin: ∂E_b/∂d ~ ω/sin ω blows up
  Eigen::VectorXd gradient;
  [[nodiscard]] bool singular() const { return near_antiparallel || bend_near_pi; }
};

/// How evaluate() forms the Hessian. `chained`: second-order AD of each side's frame (m1, m3 over
/// its ≤ 9 DOFs) and of the frames-to-energy core (12 directions), joined by the chain rule
/// ∇²E = Jᵀ C_FF J + Σ_k C_F[k] ∇²F_k — exact, like `nested_ad`, which differentiates the
/// whole stencil at once in 18 directions (kept as the reference the tests compare against).
/// A vertex side's one-ring is wider than the whole-stencil AD: its connection always chains.
enum class HessianMethod { chained, nested_ad };

inline constexpr double antiparallel_margin = 1e-3;
inline constexpr double bend_margin = 1e-2;

class PointConnection {
 public:
  /// How errors and reports name a connection of this kind.
  static constexpr std::string_view kind = "point connection";
  /// Joins sides m and n at their shared node, with the rest configuration q_rest (stencil
  /// order, see position_nodes() after construction: build q_rest from those nodes — use
  /// stencil_layout() first if needed). Sets δ̄, d̄ and the accepted δ from the rest state.
  /// Throws physics::InputError naming `name`: the sides share no node (or share more than one
  /// for a rod–triangle pair), a rod edge of one node, a triangle with a repeated node or of
  /// zero area at rest, a rest axis off the triangle's plane or outside its corner, a vertex side
  /// with fewer than 3 ring nodes, a zero-area ring triangle or normals that cancel at rest, a
  /// q_rest of the wrong size or non-finite, negative or non-finite stiffnesses. O(1).
  PointConnection(std::string name, Side m, Side n, PointStiffness k, const Eigen::VectorXd& q_rest);

  /// The position blocks' nodes, in stencil order (before construction the same order comes
  /// from stencil_layout()). For a rod side the θ slot follows its two blocks.
  [[nodiscard]] const std::vector<Index>& position_nodes() const { return nodes_; }
  [[nodiscard]] int num_dofs() const { return dofs_m_ + dofs_n_; }
  [[nodiscard]] const std::string& name() const { return name_; }
  [[nodiscard]] Index joint() const { return joint_; }
  [[nodiscard]] double rest_twist() const { return rest_twist_; }
  [[nodiscard]] double accepted_twist() const { return accepted_twist_; }
  /// +1 or −1: the sign the orientation rule gave the second side's axis.
  [[nodiscard]] double second_axis_sign() const { return sign_n_; }

  /// Energy, angles and flags at q; with `want_gradient` also dE/dq (forward-mode automatic
  /// differentiation of the energy, exact to round-off). At ω below 1e-8 the bending energy is
  /// ½k_b|d − d̄|² (equal to ½k_bω² to O(ω⁴), and differentiable there). Near the singular
  /// configurations the values are still returned, flagged; a rod edge of zero length or a
  /// triangle of zero area *now* gives non-finite values (callers check, as for the rods).
  /// Throws physics::InputError naming the connection if q has the wrong size or is not finite. Cost O(1) (18-wide
  /// forward AD, connect/src/jet.hpp, for the gradient).
  /// With `hessian`, also d²E/dq² (and the gradient), by `method` (see HessianMethod): exact
  /// to round-off, symmetric, not projected (indefinite away from rest). Cost: see docs/connect.md.
  [[nodiscard]] PointEval evaluate(const Eigen::VectorXd& q, TwistUpdate update, bool want_gradient,
                                   Eigen::MatrixXd* hessian = nullptr, HessianMethod method = HessianMethod::chained) const;

  /// After an accepted step at q: the incremental δ becomes the accepted one (by `update`),
  /// and each rod side's frame history is transported to its current tangent (what
  /// Rod::update_frames does to the rod's own). O(1).
  void accept(const Eigen::VectorXd& q, TwistUpdate update);
  /// Renames every node id (sides, joint, layout; old → new) after the node table was compacted.
  void remap_nodes(std::span<const Index> old_to_new);
  /// Both sides' frames at q (stencil order), signs of the orientation rule applied:
  /// {m1, m3, n1, n3}. Throws as evaluate() does for a q of the wrong size. O(1).
  [[nodiscard]] std::array<Vec3, 4> frames(const Eigen::VectorXd& q) const;
  /// The history accept() moves on (see ConnectionHistory). O(1).
  [[nodiscard]] ConnectionHistory history() const;
  /// Takes up history() of a connection built the same way. Throws physics::InputError naming
  /// the connection (nothing changed) if a value is not finite or a rod side's frame is not
  /// orthonormal (to 1e-9), or a non-rod side's slots are not zero. O(1).
  void restore(const ConnectionHistory& h);

 private:
  std::string name_;
  Side m_, n_;
  PointStiffness k_;
  int dofs_m_ = 0, dofs_n_ = 0;
  double sign_m_ = 1, sign_n_ = 1;
  // Per side, constants of its frame: a triangle's rest axis in (e1, e2) (2); a tet's
  // Dm⁻¹m̄3 and Dm⁻¹m̄1 (6), so that F m̄ = Ds (Dm⁻¹ m̄).
  std::array<double, 6> coef_m_{}, coef_n_{};
  Index joint_ = 0;
  std::vector<Index> nodes_;
  double rest_twist_ = 0, accepted_twist_ = 0;
  Vec3 rest_d_{0, 0, 1};
  // The constant turn of the first side's frame the twist is measured from (its columns: m'1,
  // m'2, m'3 = d̄ in m's coordinates; the identity for a straight joint).
  Eigen::Matrix3d turn_ = Eigen::Matrix3d::Identity();
};

/// The stencil's position-block nodes for sides (m, n) as PointConnection will order them
/// (a triangle rotated to start at the shared node). Throws like the constructor on sides that
/// share no node. O(1).
[[nodiscard]] std::vector<Index> stencil_layout(const std::string& name, const Side& m, const Side& n);

}  // namespace sewn::connect
