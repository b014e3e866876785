#pragma once
// The parameters of a rest point in a bilinear patch (a hexahedron face): T-junction weights and
// the sub-faces a cut facet became after refinement both need them.

#include <array>

#include <Eigen/Cholesky>
#include <Eigen/Core>

namespace sewn::refine::detail {

/// (s, t) of rest point r in the bilinear patch q0 q1 q2 q3 (q0 at (0,0), q1 (1,0), q2 (1,1)),
/// by Gauss-Newton; true if r lies on the patch (within `tolerance` times its diagonal) strictly
/// inside it (not on its border).
inline bool bilinear_inside(const std::array<Eigen::Vector3d, 4>& q, const Eigen::Vector3d& r, double& s, double& t,
                            double tolerance = 1e-12) {
  using Vec3 = Eigen::Vector3d;
  s = t = 0.5;
  const double scale = (q[2] - q[0]).norm();
  for (int it = 0; it < 30; ++it) {
    const Vec3 p = (1 - s) * (1 - t) * q[0] + s * (1 - t) * q[1] + s * t * q[2] + (1 - s) * t * q[3];
    const Vec3 ds = (1 - t) * (q[1] - q[0]) + t * (q[2] - q[3]), dt = (1 - s) * (q[3] - q[0]) + s * (q[2] - q[1]);
    Eigen::Matrix<double, 3, 2> J;
    J << ds, dt;
    const Eigen::Vector2d step = (J.transpose() * J).ldlt().solve(J.transpose() * (r - p));
    s += step[0];
    t += step[1];
    if (step.norm() < 1e-15) break;
  }
  const Vec3 p = (1 - s) * (1 - t) * q[0] + s * (1 - t) * q[1] + s * t * q[2] + (1 - s) * t * q[3];
  constexpr double eps = 1e-9;
  return (p - r).norm() <= tolerance * scale && s > eps && s < 1 - eps && t > eps && t < 1 - eps;
}

}  // namespace sewn::refine::detail
