#pragma once
// Rigid obstacles — plane, sphere, box, cone (the 2014 paper's spike) — acting on every node
// of a system through a smooth penalty, with optional smoothed Coulomb friction on planes.
// One module for the whole library: the mass-spring integrators, the rods and the Newton
// integrator all use this term.
//
// Contact model. Each obstacle has a penetration depth d(x) ≥ 0 (0 outside, the distance to
// the surface just inside it); a node of position x receives the energy E = ½ k d(x)², so
// the force is −k d ∇d and the Hessian k(∇d∇dᵀ + d ∇²d). E is C¹ everywhere (its gradient
// vanishes on the surface), and C² away from the surface. k is a per-node stiffness in N/m:
// a resting node of weight m g sinks by m g / k, and a node arriving at speed v penetrates at
// most v √(m/k) (choose k so that this is small against the mesh size; the contact
// frequency √(k/m) must be resolved by the step of an explicit integrator).
//
// Depth inside a box or cone: the smallest distance to a face is not smooth where two faces
// are equally far, so the depth is the p-norm smooth minimum (Σ d_f^(−p))^(−1/p), p = 8, of
// the distances to the faces (box: 6 planes; cone: lateral surface and base). It equals the
// true depth on every face and underestimates it near edges by at most 2^(−1/8) (8 %); it is
// smooth everywhere inside except on the cone's axis, deep inside, where the lateral
// distance has a kink (there ∇²d is taken as 0).
//
// Friction (planes, optional): the IPC-style smoothed Coulomb model with a lagged normal
// force. λ_i = k d_i is frozen at the last accepted step (step_accepted; at the first force
// evaluation before that); the friction force is F = −μ λ f1(|v_T|/ε_v) v_T/|v_T|, with v_T
// the tangential velocity, f1(y) = 2y − y² below 1 and 1 above: Coulomb's μλ when sliding
// faster than ε_v, a linear viscous law ∝ 2μλ/ε_v around rest (static friction is approximated
// by slow creep, of speed ~ ε_v · tangential load / (2μλ)). Its velocity Jacobian is symmetric
// negative semidefinite, so implicit integrators treat it as damping.

#include <span>
#include <string_view>
#include <variant>
#include <vector>

#include <Eigen/Core>

#include "sewn/physics/force_term.hpp"

namespace sewn::physics::obstacles {

using Vec3 = Eigen::Vector3d;

/// The solid half-space n·(x − point) < 0 (normal points out of the solid, into free space).
struct Plane {
  Vec3 point{0, 0, 0};
  Vec3 normal{0, 0, 1};
  double friction = 0;  ///< Coulomb coefficient μ ≥ 0 (0: frictionless)
};
struct Sphere {
  Vec3 center{0, 0, 0};
  double radius = 1;
};
/// A box of half extents h, centred at `center`, with its axes the columns of `rotation`.
struct Box {
  Vec3 center{0, 0, 0};
  Vec3 half_extents{1, 1, 1};
  Eigen::Matrix3d rotation = Eigen::Matrix3d::Identity();
};
/// A solid cone: apex, unit axis pointing from the apex into the solid (a spike pointing up
/// has axis (0,0,−1)), half angle (rad, in (0, π/2)) and height along the axis.
struct Cone {
  Vec3 apex{0, 0, 0};
  Vec3 axis{0, 0, -1};
  double half_angle = 0.3;
  double height = 1;
};
using Shape = std::variant<Plane, Sphere, Box, Cone>;

/// Penetration depth at a point with its gradient and Hessian (all zero outside).
struct Depth {
  double depth = 0;
  Vec3 gradient = Vec3::Zero();
  Eigen::Matrix3d hessian = Eigen::Matrix3d::Zero();
};
/// O(1) (a box: 6 faces). The shape must be valid (Obstacles::add checks).
[[nodiscard]] Depth depth(const Shape& shape, const Vec3& x);
/// Short name of the shape's type ("plane", "sphere", "box", "cone").
[[nodiscard]] std::string_view type_name(const Shape& shape);

class Obstacles final : public ForceTerm {
 public:
  /// k in N/m per node (finite, > 0); ε_v in m/s (finite, > 0), friction's velocity scale.
  /// Throws InputError naming the bad value.
  explicit Obstacles(double stiffness, double friction_velocity = 1e-3);
  /// Adds an obstacle; throws InputError naming the obstacle and the bad value (non-finite,
  /// zero normal or axis, radius / extents / height ≤ 0, half angle outside (0, π/2),
  /// μ < 0). Returns its index. O(1).
  Index add(const Shape& shape);
  [[nodiscard]] std::span<const Shape> shapes() const { return shapes_; }
  [[nodiscard]] double stiffness() const { return k_; }
  /// Whether add_jacobians projects each node's 3×3 penalty Hessian to PSD (default true; the
  /// sphere's and cone's curvature terms make it indefinite inside them).
  void set_project_hessians(bool on) { project_ = on; }

  [[nodiscard]] std::string_view name() const override { return "obstacles"; }
  /// Penalty and friction forces. O(nodes · obstacles).
  void add_forces(const StateView& s, std::span<double> f) const override;
  /// Σ ½ k d² (friction has no potential energy: it has a dissipation potential). O(nodes · obstacles).
  [[nodiscard]] double potential_energy(const StateView& s) const override;
  [[nodiscard]] bool dissipative() const override { return has_friction(); }
  /// Friction's Ψ = Σ μλ ε_v F1(|v_T|/ε_v), F1(y) = y² − y³/3 below 1 and y − 1/3 above
  /// (F1' = f1), λ as the forces read it. O(nodes · obstacles).
  [[nodiscard]] double dissipation(const StateView& s) const override;
  /// Diagonal blocks only: −k(∇d∇dᵀ + d∇²d) in x, friction's ∂F/∂v in v. O(nodes · obstacles).
  void add_jacobians(const StateView& s, const JacobianRequest& req) const override;
  void add_stability_rows(const StateView& s, StabilityRows& rows) const override;
  /// Freezes the friction normal forces λ at the accepted state. O(nodes · planes).
  void step_accepted(const StateView& s) override;
  void remap_nodes(std::span<const Index> old_to_new) override;

 private:
  void ensure_lambda(const StateView& s) const;
  void refresh_lambda(const StateView& s) const;  // λ = k d at s (λ is the term's mutable history)
  [[nodiscard]] bool has_friction() const;

  double k_, eps_v_;
  bool project_ = true;
  std::vector<Shape> shapes_;
  mutable std::vector<double> lambda_;  // per node × plane with friction (node-major)
  mutable bool lambda_known_ = false;
};

}  // namespace sewn::physics::obstacles
