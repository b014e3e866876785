#include "sewn/physics/shells/membrane_element.hpp"
#include "sewn/physics/shells/material_check.hpp"

#include <cmath>
#include <sstream>

#include <Eigen/Geometry>
#include <Eigen/Eigenvalues>
#include <Eigen/LU>

#include "sewn/physics/errors.hpp"

namespace sewn::physics::shells {

namespace {
using Mat32 = Eigen::Matrix<double, 3, 2>;

// Second Piola-Kirchhoff stress S = 2μE + λ_ps tr(E) I.
Eigen::Matrix2d membrane_stress(const TriPositions& x, const TriRest& rest, const MembraneMaterial& m) {
  const Eigen::Matrix2d E = membrane_strain(x, rest);
  return 2.0 * m.mu * E + m.lambda_ps * E.trace() * Eigen::Matrix2d::Identity();
}

}  // namespace

void check_shell_material(std::string_view model, double young, double poisson, double thickness) {
  if (!std::isfinite(young) || young <= 0.0 || !std::isfinite(poisson) || poisson <= -1.0 || poisson >= 0.5 ||
      !std::isfinite(thickness) || thickness <= 0.0) {
    std::ostringstream s;
    s << model << ": need E > 0, -1 < nu < 0.5 and thickness > 0, got E = " << young << " Pa, nu = " << poisson
      << ", thickness = " << thickness << " m";
    throw InputError(s.str());
  }
}

MembraneMaterial membrane_material(double young, double poisson, double thickness) {
  check_shell_material("membrane material", young, poisson, thickness);
  return {young / (2.0 * (1.0 + poisson)), young * poisson / (1.0 - poisson * poisson), thickness};
}

TriRest tri_rest(const TriPositions& X) {
  const Eigen::Vector3d a = X.col(1) - X.col(0), b = X.col(2) - X.col(0);
  const double longest = std::max({a.norm(), b.norm(), (X.col(2) - X.col(1)).norm()});
  const Eigen::Vector3d n = a.cross(b);
  const double area = 0.5 * n.norm();
  if (!std::isfinite(area) || !(area > 1e-12 * longest * longest)) {
    std::ostringstream s;
    s << "triangle: degenerate rest shape (area " << area << " m^2 for a longest edge of " << longest << " m)";
    throw InputError(s.str());
  }
  const Eigen::Vector3d e1 = a.normalized();
  const Eigen::Vector3d e2 = n.cross(a).normalized();
  Eigen::Matrix2d Dm;
  Dm << a.dot(e1), b.dot(e1), 0.0, b.dot(e2);
  Mat32 edges;
  edges.col(0) = a;
  edges.col(1) = b;
  return {edges, Dm.inverse(), area};
}

Eigen::Matrix2d membrane_strain(const TriPositions& x, const TriRest& rest) {
  Mat32 U;
  U.col(0) = (x.col(1) - x.col(0)) - rest.edges.col(0);
  U.col(1) = (x.col(2) - x.col(0)) - rest.edges.col(1);
  const Eigen::Matrix2d UX = U.transpose() * rest.edges;
  const Eigen::Matrix2d dG = UX + UX.transpose() + U.transpose() * U;
  return 0.5 * rest.Dm_inv.transpose() * dG * rest.Dm_inv;
}

Mat32 membrane_deformation(const TriPositions& x, const TriRest& rest) {
  Mat32 Ds;
  Ds.col(0) = x.col(1) - x.col(0);
  Ds.col(1) = x.col(2) - x.col(0);
  return Ds * rest.Dm_inv;
}

double membrane_energy(const TriPositions& x, const TriRest& rest, const MembraneMaterial& m) {
  const Eigen::Matrix2d E = membrane_strain(x, rest);
  return m.thickness * rest.area * (m.mu * E.squaredNorm() + 0.5 * m.lambda_ps * E.trace() * E.trace());
}

Vec9 membrane_gradient(const TriPositions& x, const TriRest& rest, const MembraneMaterial& m) {
  const Mat32 F = membrane_deformation(x, rest);
  const Eigen::Matrix2d S = membrane_stress(x, rest, m);
  const Mat32 H = m.thickness * rest.area * F * S * rest.Dm_inv.transpose();
  Vec9 g;
  g.segment<3>(0) = -H.rowwise().sum();
  g.segment<3>(3) = H.col(0);
  g.segment<3>(6) = H.col(1);
  return g;
}

namespace {

// h·Ā·Bᵀ D B with D = ∂vec(P)/∂vec(F) for the stress S_geo in the geometric term:
// dP = dF·S_geo + F(2μ dE + λ_ps tr(dE) I), dE = sym(Fᵀ dF), one column per unit dF.
Mat9 membrane_hessian_with(const Mat32& F, const Eigen::Matrix2d& S_geo, const TriRest& rest,
                           const MembraneMaterial& m) {
  const Eigen::Matrix2d I = Eigen::Matrix2d::Identity();
  elements::Mat<6> D;
  for (int c = 0; c < 6; ++c) {
    Mat32 dF = Mat32::Zero();
    dF(c % 3, c / 3) = 1.0;
    const Eigen::Matrix2d dE = 0.5 * (dF.transpose() * F + F.transpose() * dF);
    const Mat32 dP = dF * S_geo + F * (2.0 * m.mu * dE + m.lambda_ps * dE.trace() * I);
    D.col(c) = Eigen::Map<const elements::Vec<6>>(dP.data());
  }
  const auto B = elements::deformation_jacobian<2>(rest.Dm_inv);
  const Mat9 H = m.thickness * rest.area * (B.transpose() * D * B);
  return 0.5 * (H + H.transpose());
}

}  // namespace

Mat9 membrane_hessian(const TriPositions& x, const TriRest& rest, const MembraneMaterial& m) {
  const Mat32 F = membrane_deformation(x, rest);
  return membrane_hessian_with(F, membrane_stress(x, rest, m), rest, m);
}

Mat9 membrane_hessian_psd(const TriPositions& x, const TriRest& rest, const MembraneMaterial& m) {
  const Mat32 F = membrane_deformation(x, rest);
  const Eigen::Matrix2d S = membrane_stress(x, rest, m);
  // S = Σ σ_i s_i s_iᵀ (2×2, closed form); the geometric term dF:(dF S) = Σ_rows r S rᵀ is
  // PSD with S⁺ = Σ max(σ_i, 0) s_i s_iᵀ, and the material term dE:C:dE is PSD for every
  // admissible (μ > 0, μ + λ_ps > 0) material. Exact wherever both principal stresses are ≥ 0.
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d> eig;
  eig.computeDirect(S);
  const Eigen::Vector2d sigma = eig.eigenvalues();
  if (sigma.minCoeff() >= 0.0) return membrane_hessian_with(F, S, rest, m);
  const Eigen::Matrix2d V = eig.eigenvectors();
  const Eigen::Matrix2d S_plus = V * sigma.cwiseMax(0.0).asDiagonal() * V.transpose();
  return membrane_hessian_with(F, S_plus, rest, m);
}

}  // namespace sewn::physics::shells
