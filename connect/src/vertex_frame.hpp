#pragma once
// The frame of a shell's interior vertex (PHYSICS_NOTES §3.5), and a frame's derivatives as
// the point connection's chained Hessian takes them. Private to the module (connect/src).
//
// With the joint x0 and its one-ring x1..xv in order (triangles (x0, xi, xi+1), the last
// closing on x1), edges ei = xi − x0:
//   m3 = sign · hat(w),  w = Σ αi hat(ei × ei+1),  αi = the corner angle atan2(|ei × ei+1|, ei·ei+1)
//   m1 = hat(e1 − (e1·m̂3) m̂3)   (m̂3 = hat(w): the first ring edge projected on the tangent plane)
// The frame depends on the whole one-ring (3(v + 1) DOFs), more than the point connection's
// whole-stencil AD carries; its derivatives come from 6-direction jets per triangle and per
// frame map, joined by the chain rule.

#include <array>

#include <Eigen/Core>

namespace sewn::connect::detail {

/// A side's frame (m1, m3) as 6 values, with their Jacobian (6 × DOFs) and each value's
/// second derivatives (DOFs × DOFs) over the side's DOFs (empty if not asked for).
struct FrameJet {
  Eigen::Matrix<double, 6, 1> value;
  Eigen::MatrixXd jacobian;
  std::array<Eigen::MatrixXd, 6> hessian;
};

/// The vertex frame {m1, m3} of the side whose DOFs start at q[at]: x0, then `ring` one-ring
/// positions. Non-finite where w = 0 or e1 ∥ w (the caller refuses those at rest). O(ring).
[[nodiscard]] std::array<Eigen::Vector3d, 2> vertex_frame(const Eigen::VectorXd& q, int at, int ring, double sign);

/// The same with its first (and, if second_order, second) derivatives over the side's
/// 3(ring + 1) DOFs. O(ring²) with second derivatives, else O(ring).
[[nodiscard]] FrameJet vertex_frame_jet(const Eigen::VectorXd& q, int at, int ring, double sign, bool second_order);

}  // namespace sewn::connect::detail
