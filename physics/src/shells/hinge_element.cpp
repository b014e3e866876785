#include "sewn/physics/shells/hinge_element.hpp"

#include <cmath>
#include <numbers>
#include <sstream>

#include <Eigen/Geometry>
#include <unsupported/Eigen/AutoDiff>

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

Mat12 dihedral_hessian(const HingePositions& x) {
  if (!well_shaped(x)) return Mat12::Zero();
  using Dual = Eigen::AutoDiffScalar<Vec12>;
  Eigen::Matrix<Dual, 3, 4> xd;
  for (int j = 0; j < 4; ++j)
    for (int a = 0; a < 3; ++a) xd(a, j) = Dual(x(a, j), 12, 3 * j + a);
  const Eigen::Matrix<Dual, 12, 1> gd = angle_gradient<Dual>(xd);
  Mat12 ddtheta;
  for (int r = 0; r < 12; ++r) ddtheta.row(r) = gd[r].derivatives().transpose();
  return 0.5 * (ddtheta + ddtheta.transpose());
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
