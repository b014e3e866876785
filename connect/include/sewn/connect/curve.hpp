#pragma once
// Curve connections (the 2019 paper's §4; PHYSICS_NOTES §3.5): the angle energy along edges
// that two bodies share — a rod embedded along shell or solid edges, two shells across a
// non-manifold edge, a shell on a solid's surface curve. At a shared edge (a, b) both sides'
// frames have the edge's direction e = hat(x_b − x_a) as axis, so no transport is needed:
//   δ = signed angle from m1 to n1 about e = atan2(n1·(e×m1), n1·m1),
//   E = ½ k l̄ (δ − δ̄)²,
// with k the stiffness per unit length (N/rad: N·m/rad of torque per metre of curve) and l̄
// the edge's rest length, so that a curve's energy does not depend on how finely it is cut
// into edges, and stretching the edge does not feed into it. One EdgeConnection per edge (and
// per pair of sides: a rod inside a solid has one per tet face around each of its edges).
//
// Sides at an edge and their m1 (always ⟂ e):
//   RodEdgeSide — the rod's material frame m1 of that edge (from/to are a, b in either order);
//   FaceSide    — the unit normal of the triangle (a, b, apex): a shell boundary edge, or one
//                 tet face around an edge (the rod-in-solid case);
//   HingeSide   — hat(n_A + n_B) of the triangles (a, b, left) and (b, a, right), consistently
//                 oriented: a shell interior edge, or a solid's surface curve (its two
//                 exterior faces).
// Orientation rule: the second side's m1 is negated if m̄1·n̄1 < 0 at rest, so |δ̄| ≤ π/2 and
// the direct angle starts as far from its wrap as it can.
//
// Stencil DOF order q: x_a (3), x_b (3), then side m's extra DOFs, then side n's:
//   rod: θ (1), face: x_apex (3), hinge: x_left (3), x_right (3).

#include <optional>
#include <string>
#include <variant>
#include <vector>

#include <Eigen/Core>

#include "sewn/connect/point.hpp"

namespace sewn::connect {

/// The triangle (a, b, apex) as a side of the edge (a, b).
struct FaceSide {
  Index apex = 0;
};
/// The two triangles (a, b, left) and (b, a, right) as one side of the edge (a, b).
struct HingeSide {
  Index left = 0, right = 0;
};
using EdgeSide = std::variant<RodEdgeSide, FaceSide, HingeSide>;

/// Values at one configuration; `gradient` dE/dq in stencil order (empty if not asked).
struct EdgeEval {
  double energy = 0;
  double twist = 0;      ///< δ by the update asked for
  double twist_raw = 0;  ///< the direct δ ∈ (−π, π]
  /// A frame could not be built here: the edge, a rod edge or a triangle collapsed, or a
  /// hinge folded onto itself (n_A + n_B ≈ 0); values are then not meaningful.
  bool degenerate = false;
  Eigen::VectorXd gradient;
};

/// How evaluate() differentiates. `reduced`: δ alone, in the positions relative to x_a (the
/// energy does not change when the whole stencil moves, so x_a's derivatives are minus the sum
/// of the others'), a rod side's θ exactly (δ is affine in it: ∂δ/∂θ = ∓1, no cross terms),
/// then E = ½kl̄(δ − δ̄)² by the chain rule — 6 AD directions for a rod along a face instead of
/// 10. `whole_stencil`: second-order AD of E in every stencil DOF at once (18 directions), the
/// reference the tests compare against. Both exact to round-off.
enum class EdgeDerivatives { reduced, whole_stencil };

class EdgeConnection {
 public:
  /// How errors and reports name a connection of this kind.
  static constexpr std::string_view kind = "curve connection";
  /// Joins sides m and n along the edge (a, b) with stiffness `k_per_length` (N/rad, ≥ 0) at
  /// the rest configuration q_rest (stencil order; stencil_nodes() gives the nodes, which
  /// edge_stencil_nodes() gives before construction). Sets l̄, δ̄ and the accepted δ.
  /// Throws physics::InputError naming `name`: a = b, a rod side that is not the edge (a, b),
  /// an apex that is a or b or repeated, a zero-length edge, a zero-area triangle or a hinge
  /// folded flat onto itself at rest, a wrong-size or non-finite q_rest, a negative or
  /// non-finite stiffness. O(1).
  EdgeConnection(std::string name, Index a, Index b, EdgeSide m, EdgeSide n, double k_per_length,
                 const Eigen::VectorXd& q_rest);

  /// The position blocks' nodes in stencil order (a, b, then the sides' apices).
  [[nodiscard]] const std::vector<Index>& stencil_nodes() const { return nodes_; }
  [[nodiscard]] int num_dofs() const { return 6 + extra_m_ + extra_n_; }
  /// Where side 0 (m) or 1 (n)'s θ sits in the stencil if that side is a rod, else -1.
  [[nodiscard]] int angle_slot(int side) const;
  [[nodiscard]] const std::string& name() const { return name_; }
  [[nodiscard]] double rest_length() const { return rest_length_; }
  [[nodiscard]] double rest_twist() const { return rest_twist_; }
  [[nodiscard]] double accepted_twist() const { return accepted_twist_; }
  /// +1 or −1: the sign the orientation rule gave the second side's m1.
  [[nodiscard]] double second_sign() const { return sign_n_; }

  /// Energy and angles at q; with `want_gradient` dE/dq, with `hessian` also d²E/dq² (exact,
  /// forward-mode AD by `method`; symmetric, not projected). The values are the same whatever
  /// is asked. Throws physics::InputError naming the connection if q has the wrong size or is
  /// not finite. O(1).
  [[nodiscard]] EdgeEval evaluate(const Eigen::VectorXd& q, TwistUpdate update, bool want_gradient,
                                  Eigen::MatrixXd* hessian = nullptr,
                                  EdgeDerivatives method = EdgeDerivatives::reduced) const;
  /// After an accepted step at q: the accepted δ moves on (by `update`) and a rod side's frame
  /// history is transported to its current tangent (as Rod::update_frames does). O(1).
  void accept(const Eigen::VectorXd& q, TwistUpdate update);
  /// Renames every node id (old → new) after the node table was compacted.
  void remap_nodes(std::span<const Index> old_to_new);
  /// The history accept() moves on (ConnectionHistory, point.hpp). O(1).
  [[nodiscard]] ConnectionHistory history() const;
  /// Takes up history() of a connection built the same way; throws as PointConnection::restore.
  void restore(const ConnectionHistory& h);

 private:
  std::string name_;
  Index a_, b_;
  EdgeSide m_, n_;
  double k_;
  int extra_m_ = 0, extra_n_ = 0;
  double sign_n_ = 1;
  std::vector<Index> nodes_;
  double rest_length_ = 0, rest_twist_ = 0, accepted_twist_ = 0;
};

/// The stencil's position nodes for edge (a, b) with sides m, n (a, b, then the apices). O(1).
[[nodiscard]] std::vector<Index> edge_stencil_nodes(Index a, Index b, const EdgeSide& m, const EdgeSide& n);

}  // namespace sewn::connect
