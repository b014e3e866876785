#pragma once
// What patch and Morley bending share (private to physics/src/shells): a rest triangle in an
// orthonormal frame of its plane, its barycentric gradients, and the plate energy's matrix Q in
// the coefficients β of the three edge bubbles b_m = λ_{m+1}λ_{m+2}:
//   E = ½ βᵀQβ = Ā (D/2)[(1-ν) tr(K²) + ν (tr K)²],  K = Σ_m β_m ∇²b_m.

#include <algorithm>
#include <array>
#include <cmath>
#include <sstream>
#include <string>

#include <Eigen/Core>
#include <Eigen/LU>

#include "sewn/physics/errors.hpp"
#include "sewn/physics/shells/patch_element.hpp"

namespace sewn::physics::shells::detail {

struct PlateQuadratic {
  double area = 0.0;
  Eigen::Matrix<double, 2, 3> corners;  ///< in the frame, corner 0 at the origin
  Eigen::Matrix2d Dm_inv;               ///< maps q - corner 0 to (λ1, λ2)
  Eigen::Matrix<double, 2, 3> grad;     ///< column a: ∇λ_a
  Eigen::Matrix3d Q;
};

/// From the rest corners (columns of X). Throws InputError "<who>: degenerate rest triangle".
inline PlateQuadratic plate_quadratic(const Eigen::Matrix3d& X, const PlateMaterial& m, const std::string& who) {
  PlateQuadratic r;
  const Eigen::Vector3d e1 = X.col(1) - X.col(0), e2 = X.col(2) - X.col(0);
  const Eigen::Vector3d n = e1.cross(e2);
  r.area = 0.5 * n.norm();
  const double longest2 = std::max({e1.squaredNorm(), e2.squaredNorm(), (X.col(2) - X.col(1)).squaredNorm()});
  if (!std::isfinite(r.area) || !(r.area > 1e-12 * longest2)) {
    std::ostringstream s;
    s << who << ": degenerate rest triangle (area " << r.area << " m^2)";
    throw InputError(s.str());
  }
  const Eigen::Vector3d u = e1.normalized(), v = n.normalized().cross(u);
  for (int a = 0; a < 3; ++a) r.corners.col(a) << (X.col(a) - X.col(0)).dot(u), (X.col(a) - X.col(0)).dot(v);
  Eigen::Matrix2d Dm;
  Dm << r.corners.col(1) - r.corners.col(0), r.corners.col(2) - r.corners.col(0);
  r.Dm_inv = Dm.inverse();
  r.grad.col(1) = r.Dm_inv.row(0).transpose();
  r.grad.col(2) = r.Dm_inv.row(1).transpose();
  r.grad.col(0) = -r.grad.col(1) - r.grad.col(2);
  std::array<Eigen::Matrix2d, 3> B;  // ∇²b_m
  for (int k = 0; k < 3; ++k) {
    const Eigen::Vector2d ga = r.grad.col((k + 1) % 3), gb = r.grad.col((k + 2) % 3);
    B[static_cast<std::size_t>(k)] = ga * gb.transpose() + gb * ga.transpose();
  }
  for (int a = 0; a < 3; ++a)
    for (int b = 0; b < 3; ++b) {
      const auto& Ba = B[static_cast<std::size_t>(a)];
      const auto& Bb = B[static_cast<std::size_t>(b)];
      r.Q(a, b) = r.area * m.stiffness * ((1.0 - m.poisson) * (Ba * Bb).trace() + m.poisson * Ba.trace() * Bb.trace());
    }
  return r;
}

}  // namespace sewn::physics::shells::detail
