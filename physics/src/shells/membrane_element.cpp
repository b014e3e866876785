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
Eigen::Matrix2d stress_of(const Eigen::Matrix2d& E, const MembraneMaterial& m) {
  return 2.0 * m.mu * E + m.lambda_ps * E.trace() * Eigen::Matrix2d::Identity();
}

Eigen::Matrix2d membrane_stress(const TriPositions& x, const TriRest& rest, const MembraneMaterial& m) {
  return stress_of(membrane_strain(x, rest), m);
}

double energy_of(const Eigen::Matrix2d& E, const TriRest& rest, const MembraneMaterial& m) {
  return m.thickness * rest.area * (m.mu * E.squaredNorm() + 0.5 * m.lambda_ps * E.trace() * E.trace());
}

// ∂W/∂x from F and the stress: the columns of h·Ā F S Dm⁻ᵀ are the forces' negatives on nodes
// 1 and 2, node 0 takes minus their sum.
Vec9 gradient_of(const TriPositions& x, const Eigen::Matrix2d& S, const TriRest& rest, const MembraneMaterial& m) {
  const Mat32 H = m.thickness * rest.area * membrane_deformation(x, rest) * S * rest.Dm_inv.transpose();
  Vec9 g;
  g.segment<3>(0) = -H.rowwise().sum();
  g.segment<3>(3) = H.col(0);
  g.segment<3>(6) = H.col(1);
  return g;
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
  return energy_of(membrane_strain(x, rest), rest, m);
}

Vec9 membrane_gradient(const TriPositions& x, const TriRest& rest, const MembraneMaterial& m) {
  return gradient_of(x, membrane_stress(x, rest, m), rest, m);
}

double membrane_energy_gradient(const TriPositions& x, const TriRest& rest, const MembraneMaterial& m, Vec9& g) {
  const Eigen::Matrix2d E = membrane_strain(x, rest);
  g = gradient_of(x, stress_of(E, m), rest, m);
  return energy_of(E, rest, m);
}

namespace {

// The Hessian block by block, with F = Σ_a x_a g_aᵀ (g_a: node a's row of the rest shape
// functions' gradients, g_0 = -g_1 - g_2) and f_a = F g_a: the second variation of h·Ā·W along
// node a moved by u and node b by v, δF_b:(δF_a S + F(2μ δE_a + λ_ps tr(δE_a) I)) with
// δE_a = sym(Fᵀu g_aᵀ), is uᵀ H_ab v with
//   H_ab = h·Ā [(g_aᵀ S_geo g_b) I + μ (g_a·g_b) F Fᵀ + μ f_b f_aᵀ + λ_ps f_a f_bᵀ].
// ~0.3k flops, where forming ∂P/∂F column by column and Bᵀ D B took ~2k.
Mat9 membrane_hessian_with(const Mat32& F, const Eigen::Matrix2d& S_geo, const TriRest& rest,
                           const MembraneMaterial& m) {
  const double w = m.thickness * rest.area;
  Eigen::Matrix<double, 2, 3> g;  // column a: g_a
  g.col(1) = rest.Dm_inv.row(0).transpose();
  g.col(2) = rest.Dm_inv.row(1).transpose();
  g.col(0) = -g.col(1) - g.col(2);
  const Eigen::Matrix3d f = F * g;  // column a: f_a
  const Eigen::Matrix3d FFt = (w * m.mu) * (F * F.transpose());
  const Eigen::Matrix3d geo = w * (g.transpose() * S_geo * g);  // (a, b): g_aᵀ S g_b
  const Eigen::Matrix3d gg = g.transpose() * g;
  Mat9 H;
  for (int a = 0; a < 3; ++a)
    for (int b = a; b < 3; ++b) {
      Eigen::Matrix3d blk = gg(a, b) * FFt + (w * m.mu) * f.col(b) * f.col(a).transpose() +
                            (w * m.lambda_ps) * f.col(a) * f.col(b).transpose();
      blk.diagonal().array() += geo(a, b);
      H.block<3, 3>(3 * a, 3 * b) = blk;
      if (b != a) H.block<3, 3>(3 * b, 3 * a) = blk.transpose();
    }
  return H;
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
