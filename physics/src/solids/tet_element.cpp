#include "sewn/physics/solids/tet_element.hpp"

#include <cmath>
#include <sstream>

#include <Eigen/LU>

#include "sewn/physics/errors.hpp"

namespace sewn::physics::solids {

namespace {

using elements::cofactor;

Eigen::Matrix3d skew(const Eigen::Vector3d& a) {
  Eigen::Matrix3d S;
  S << 0, -a.z(), a.y(), a.z(), 0, -a.x(), -a.y(), a.x(), 0;
  return S;
}

// λ' and α of the stable neo-Hookean form (see the header).
struct SnhParams {
  double lambda, alpha;
};
SnhParams snh(const Lame& m) {
  const double lp = m.lambda + m.mu;
  return {lp, 1.0 + m.mu / lp};
}

}  // namespace

Lame lame_from_young(double young, double poisson) {
  if (!std::isfinite(young) || young <= 0.0 || !std::isfinite(poisson) || poisson <= -1.0 || poisson >= 0.5) {
    std::ostringstream s;
    s << "elastic material: need Young's modulus E > 0 and Poisson's ratio -1 < nu < 0.5, got E = " << young
      << " Pa, nu = " << poisson;
    throw InputError(s.str());
  }
  return {young / (2.0 * (1.0 + poisson)), young * poisson / ((1.0 + poisson) * (1.0 - 2.0 * poisson))};
}

TetRest tet_rest(const TetPositions& X) {
  Eigen::Matrix3d Dm;
  for (int j = 0; j < 3; ++j) Dm.col(j) = X.col(j + 1) - X.col(0);
  double longest = 0.0;
  for (int i = 0; i < 4; ++i)
    for (int j = i + 1; j < 4; ++j) longest = std::max(longest, (X.col(i) - X.col(j)).norm());
  const double volume = std::abs(Dm.determinant()) / 6.0;
  if (!std::isfinite(volume) || !(volume > 1e-12 * longest * longest * longest)) {
    std::ostringstream s;
    s << "tetrahedron: degenerate rest shape (volume " << volume << " m^3 for a longest edge of " << longest << " m)";
    throw InputError(s.str());
  }
  return {Dm, Dm.inverse(), volume};
}

Eigen::Matrix3d displacement_gradient(const TetPositions& x, const TetRest& rest) {
  Eigen::Matrix3d dD;
  for (int j = 0; j < 3; ++j) dD.col(j) = (x.col(j + 1) - x.col(0)) - rest.Dm.col(j);
  return dD * rest.Dm_inv;
}

Eigen::Matrix3d deformation_gradient(const TetPositions& x, const TetRest& rest) {
  Eigen::Matrix3d Ds;
  for (int j = 0; j < 3; ++j) Ds.col(j) = x.col(j + 1) - x.col(0);
  return Ds * rest.Dm_inv;
}

double energy_density(TetLaw law, const Eigen::Matrix3d& H, const Lame& m) {
  // Every quantity below is formed from H = F - I, never as a difference of O(1) terms.
  if (law == TetLaw::stvk) {
    const Eigen::Matrix3d E = 0.5 * (H + H.transpose() + H.transpose() * H);
    return m.mu * E.squaredNorm() + 0.5 * m.lambda * E.trace() * E.trace();
  }
  // ½μ(tr FᵀF - 3) + ½λ'((J - α)² - (1 - α)²), the constant taken off so that the rest
  // state has zero energy, rewritten as ½μ(|H|² + 2 tr H) + ½λ'(J - 1)² - μ(J - 1) with
  // J - 1 = tr H + ½((tr H)² - tr H²) + det H.
  const SnhParams p = snh(m);
  const double t = H.trace();
  const double j1 = t + 0.5 * (t * t - (H * H).trace()) + H.determinant();
  return 0.5 * m.mu * (H.squaredNorm() + 2.0 * t) + 0.5 * p.lambda * j1 * j1 - m.mu * j1;
}

Eigen::Matrix3d first_piola(TetLaw law, const Eigen::Matrix3d& F, const Lame& m) {
  if (law == TetLaw::stvk) {
    const Eigen::Matrix3d E = 0.5 * (F.transpose() * F - Eigen::Matrix3d::Identity());
    return F * (2.0 * m.mu * E + m.lambda * E.trace() * Eigen::Matrix3d::Identity());
  }
  const SnhParams p = snh(m);
  return m.mu * F + p.lambda * (F.determinant() - p.alpha) * cofactor(F);
}

elements::Mat<9> piola_derivative(TetLaw law, const Eigen::Matrix3d& F, const Lame& m) {
  elements::Mat<9> D;
  if (law == TetLaw::stvk) {
    // dP = dF·S + F·(2μ dE + λ tr(dE) I), dE = ½(dFᵀF + FᵀdF), one column per unit dF.
    const Eigen::Matrix3d I = Eigen::Matrix3d::Identity();
    const Eigen::Matrix3d E = 0.5 * (F.transpose() * F - I);
    const Eigen::Matrix3d S = 2.0 * m.mu * E + m.lambda * E.trace() * I;
    for (int c = 0; c < 9; ++c) {
      Eigen::Matrix3d dF = Eigen::Matrix3d::Zero();
      dF(c % 3, c / 3) = 1.0;
      const Eigen::Matrix3d dE = 0.5 * (dF.transpose() * F + F.transpose() * dF);
      const Eigen::Matrix3d dP = dF * S + F * (2.0 * m.mu * dE + m.lambda * dE.trace() * I);
      D.col(c) = Eigen::Map<const elements::Vec<9>>(dP.data());
    }
    return D;
  }
  // μI + λ' g gᵀ + λ'(J - α) ∂²J/∂F², g = vec(cof F); ∂²J/∂f_a∂f_b are ±skew(f_c).
  const SnhParams p = snh(m);
  const Eigen::Matrix3d C = cofactor(F);
  const elements::Vec<9> g = Eigen::Map<const elements::Vec<9>>(C.data());
  D = m.mu * elements::Mat<9>::Identity() + p.lambda * g * g.transpose();
  const double s = p.lambda * (F.determinant() - p.alpha);
  const Eigen::Matrix3d H01 = -skew(F.col(2)), H02 = skew(F.col(1)), H12 = -skew(F.col(0));
  D.block<3, 3>(0, 3) += s * H01;
  D.block<3, 3>(3, 0) += s * H01.transpose();
  D.block<3, 3>(0, 6) += s * H02;
  D.block<3, 3>(6, 0) += s * H02.transpose();
  D.block<3, 3>(3, 6) += s * H12;
  D.block<3, 3>(6, 3) += s * H12.transpose();
  return D;
}

double tet_energy(TetLaw law, const TetPositions& x, const TetRest& rest, const Lame& m) {
  return rest.volume * energy_density(law, displacement_gradient(x, rest), m);
}

Vec12 tet_gradient(TetLaw law, const TetPositions& x, const TetRest& rest, const Lame& m) {
  // ∂/∂x_{1..3} = V̄ P Dm⁻ᵀ (columns), ∂/∂x_0 = -Σ.
  const Eigen::Matrix3d H = rest.volume * first_piola(law, deformation_gradient(x, rest), m) * rest.Dm_inv.transpose();
  Vec12 g;
  g.segment<3>(0) = -H.rowwise().sum();
  for (int j = 0; j < 3; ++j) g.segment<3>(3 * j + 3) = H.col(j);
  return g;
}

Mat12 tet_hessian(TetLaw law, const TetPositions& x, const TetRest& rest, const Lame& m) {
  const auto B = elements::deformation_jacobian<3>(rest.Dm_inv);
  const elements::Mat<9> D = piola_derivative(law, deformation_gradient(x, rest), m);
  Mat12 H = rest.volume * (B.transpose() * D * B);
  return 0.5 * (H + H.transpose());
}

}  // namespace sewn::physics::solids
