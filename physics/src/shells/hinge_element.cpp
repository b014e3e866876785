#include "sewn/physics/shells/hinge_element.hpp"

#include <array>
#include <cmath>
#include <numbers>
#include <sstream>

#include <Eigen/Geometry>

#include "sewn/physics/errors.hpp"
#include "sewn/physics/shells/material_check.hpp"

namespace sewn::physics::shells {

namespace {

// Whether both faces and the edge are far enough from degenerate for ∇θ to be defined.
bool well_shaped(const HingePositions& x) {
  const Eigen::Vector3d e = x.col(2) - x.col(1);
  const double le2 = e.squaredNorm();
  const double a = (x.col(1) - x.col(0)).cross(x.col(2) - x.col(0)).squaredNorm();
  const double b = (x.col(2) - x.col(3)).cross(x.col(1) - x.col(3)).squaredNorm();
  const double tiny = 1e-30 * le2 * le2;
  return le2 > 0.0 && a > tiny && b > tiny && std::isfinite(a + b);
}

// The closed-form ∇θ of PHYSICS_NOTES §3.2, on any scalar type (double, dual numbers).
template <class T>
Eigen::Matrix<T, 12, 1> angle_gradient(const Eigen::Matrix<T, 3, 4>& x) {
  using V = Eigen::Matrix<T, 3, 1>;
  using std::sqrt;
  const V x0 = x.col(0), x1 = x.col(1), x2 = x.col(2), x3 = x.col(3);
  const V e = x2 - x1;
  const T le2 = e.squaredNorm();
  const T le = sqrt(le2);
  const V nA = (x1 - x0).cross(x2 - x0);  // |nA| = 2 A_A
  const V nB = (x2 - x3).cross(x1 - x3);
  // -n̂/h with h = 2A/|e| is -n·|e|/|n|².
  const V g0 = nA * (-le / nA.squaredNorm());
  const V g3 = nB * (-le / nB.squaredNorm());
  const T sA = (x0 - x1).dot(e) / le2;
  const T sB = (x3 - x1).dot(e) / le2;
  Eigen::Matrix<T, 12, 1> g;
  g.template segment<3>(0) = g0;
  g.template segment<3>(3) = g0 * (sA - 1.0) + g3 * (sB - 1.0);
  g.template segment<3>(6) = g0 * (-sA) + g3 * (-sB);
  g.template segment<3>(9) = g3;
  return g;
}

}  // namespace

double wrap_angle(double d) {
  constexpr double pi = std::numbers::pi;
  while (d > pi) d -= 2.0 * pi;
  while (d <= -pi) d += 2.0 * pi;
  return d;
}

double hinge_stiffness(double young, double poisson, double thickness) {
  check_shell_material("hinge bending", young, poisson, thickness);
  const double D = young * thickness * thickness * thickness / (12.0 * (1.0 - poisson * poisson));
  return D / 6.0;
}

HingeRest hinge_rest(const HingePositions& X) {
  const Eigen::Vector3d e = X.col(2) - X.col(1);
  const double aA = 0.5 * (X.col(1) - X.col(0)).cross(X.col(2) - X.col(0)).norm();
  const double aB = 0.5 * (X.col(2) - X.col(3)).cross(X.col(1) - X.col(3)).norm();
  const double le2 = e.squaredNorm();
  if (!std::isfinite(aA + aB + le2) || !(aA > 1e-12 * le2) || !(aB > 1e-12 * le2)) {
    std::ostringstream s;
    s << "hinge: degenerate rest shape (face areas " << aA << " and " << aB << " m^2, hinge edge " << std::sqrt(le2)
      << " m)";
    throw InputError(s.str());
  }
  return {dihedral_angle(X), 3.0 * le2 / (aA + aB)};
}

double dihedral_angle(const HingePositions& x) {
  const Eigen::Vector3d x0 = x.col(0), x1 = x.col(1), x2 = x.col(2), x3 = x.col(3);
  const Eigen::Vector3d nA = (x1 - x0).cross(x2 - x0);
  const Eigen::Vector3d nB = (x2 - x3).cross(x1 - x3);
  const Eigen::Vector3d e = (x2 - x1).normalized();
  // atan2 is scale-invariant in its two arguments, so the normals need no normalising.
  return std::atan2(nA.cross(nB).dot(e), nA.dot(nB));
}

Vec12 dihedral_gradient(const HingePositions& x) {
  if (!well_shaped(x)) return Vec12::Zero();
  return angle_gradient<double>(x);
}

double hinge_energy(const HingePositions& x, const HingeRest& rest, double k_b) {
  const double d = wrap_angle(dihedral_angle(x) - rest.theta);
  return k_b * rest.weight * d * d;
}

Vec12 hinge_gradient(const HingePositions& x, const HingeRest& rest, double k_b) {
  const double d = wrap_angle(dihedral_angle(x) - rest.theta);
  return (2.0 * k_b * rest.weight * d) * dihedral_gradient(x);
}

namespace {

using Mat3 = Eigen::Matrix3d;
using Vec3 = Eigen::Vector3d;

Mat3 cross_matrix(const Vec3& a) {
  Mat3 m;
  m << 0.0, -a.z(), a.y(), a.z(), 0.0, -a.x(), -a.y(), a.x(), 0.0;
  return m;
}

// One wing's part of ∇θ, u = -|e| n/|n|² (n the wing face's unnormalised normal), and its
// derivative with respect to one node given that node's dn/dx and d|e|/dx (a row):
// du = -n/|n|² d|e| - |e|/|n|² (I - 2 n̂n̂ᵀ) dn.
struct Wing {
  Vec3 u;
  Vec3 n_over;  // n/|n|²
  Mat3 reflect;  // |e|/|n|² (I - 2 n̂n̂ᵀ)
  Wing(const Vec3& n, double le) {
    const double nn = n.squaredNorm();
    n_over = n / nn;
    u = n * (-le / nn);  // as angle_gradient forms it, so that both give the same ∇θ
    reflect = (le / nn) * (Mat3::Identity() - (2.0 / nn) * n * n.transpose());
  }
  [[nodiscard]] Mat3 d(const Mat3& dn, const Eigen::RowVector3d& dle) const { return -n_over * dle - reflect * dn; }
};

}  // namespace

// ∇²θ by differentiating the closed-form ∇θ (angle_gradient) by hand: g0 = u_A, g3 = u_B,
// g1 = (s_A - 1)u_A + (s_B - 1)u_B, g2 = -s_A u_A - s_B u_B, with the wing normals' derivatives
// n_A = (x1-x0)×(x2-x0): ∂n_A/∂x0 = [e]×, ∂/∂x1 = -[x2-x0]×, ∂/∂x2 = [x1-x0]×;
// n_B = (x2-x3)×(x1-x3): ∂n_B/∂x1 = [x2-x3]×, ∂/∂x2 = -[x1-x3]×, ∂/∂x3 = -[e]×;
// s = (x_w - x1)·e/|e|²: ∂s/∂x_w = e/|e|², ∂s/∂x2 = ((x_w - x1) - 2 s e)/|e|², ∂s/∂x1 the
// negated sum. About 1k flops where forward AD with 12-wide duals took ~2.5k and its copies.
void dihedral_derivatives(const HingePositions& x, Vec12& g, Mat12& H) {
  if (!well_shaped(x)) {
    g.setZero();
    H.setZero();
    return;
  }
  const Vec3 x0 = x.col(0), x1 = x.col(1), x2 = x.col(2), x3 = x.col(3);
  const Vec3 e = x2 - x1;
  const double le2 = e.squaredNorm(), le = std::sqrt(le2);
  const Eigen::RowVector3d dle = e.transpose() / le;  // ∂|e|/∂x2; -that for x1
  const Wing A((x1 - x0).cross(x2 - x0), le), B((x2 - x3).cross(x1 - x3), le);
  const double sA = (x0 - x1).dot(e) / le2, sB = (x3 - x1).dot(e) / le2;
  // Derivatives of u_A, u_B and s_A, s_B by node (0..3); u_A does not depend on x3, u_B on x0.
  std::array<Mat3, 4> dA, dB;
  dA[0] = A.d(cross_matrix(e), Eigen::RowVector3d::Zero());
  dA[1] = A.d(-cross_matrix(x2 - x0), -dle);
  dA[2] = A.d(cross_matrix(x1 - x0), dle);
  dA[3].setZero();
  dB[0].setZero();
  dB[1] = B.d(cross_matrix(x2 - x3), -dle);
  dB[2] = B.d(-cross_matrix(x1 - x3), dle);
  dB[3] = B.d(-cross_matrix(e), Eigen::RowVector3d::Zero());
  std::array<Eigen::RowVector3d, 4> dsA, dsB;
  dsA[0] = e.transpose() / le2;
  dsA[2] = ((x0 - x1) - 2.0 * sA * e).transpose() / le2;
  dsA[1] = -dsA[0] - dsA[2];
  dsA[3].setZero();
  dsB[3] = e.transpose() / le2;
  dsB[2] = ((x3 - x1) - 2.0 * sB * e).transpose() / le2;
  dsB[1] = -dsB[3] - dsB[2];
  dsB[0].setZero();
  g.segment<3>(0) = A.u;
  g.segment<3>(3) = A.u * (sA - 1.0) + B.u * (sB - 1.0);
  g.segment<3>(6) = A.u * (-sA) + B.u * (-sB);
  g.segment<3>(9) = B.u;
  for (int j = 0; j < 4; ++j) {
    const auto J = static_cast<std::size_t>(j);
    const Mat3 uA_sA = A.u * dsA[J], uB_sB = B.u * dsB[J];
    H.block<3, 3>(0, 3 * j) = dA[J];
    H.block<3, 3>(3, 3 * j) = (sA - 1.0) * dA[J] + uA_sA + (sB - 1.0) * dB[J] + uB_sB;
    H.block<3, 3>(6, 3 * j) = -sA * dA[J] - uA_sA - sB * dB[J] - uB_sB;
    H.block<3, 3>(9, 3 * j) = dB[J];
  }
  H = (0.5 * (H + H.transpose())).eval();
}

Mat12 dihedral_hessian(const HingePositions& x) {
  Vec12 g;
  Mat12 H;
  dihedral_derivatives(x, g, H);
  return H;
}

Mat12 hinge_hessian(const HingePositions& x, const HingeRest& rest, double k_b) {
  if (!well_shaped(x)) return Mat12::Zero();
  const Vec12 g = angle_gradient<double>(x);
  const double d = wrap_angle(dihedral_angle(x) - rest.theta);
  return 2.0 * k_b * rest.weight * (g * g.transpose() + d * dihedral_hessian(x));
}

Mat12 hinge_hessian_gauss_newton(const HingePositions& x, const HingeRest& rest, double k_b) {
  if (!well_shaped(x)) return Mat12::Zero();
  const Vec12 g = angle_gradient<double>(x);
  return (2.0 * k_b * rest.weight) * (g * g.transpose());
}

}  // namespace sewn::physics::shells
