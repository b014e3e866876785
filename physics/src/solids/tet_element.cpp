#include "sewn/physics/solids/tet_element.hpp"

#include <array>
#include <cmath>
#include <sstream>

#include <Eigen/Eigenvalues>
#include <Eigen/LU>
#include <Eigen/SVD>

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

namespace {

// StVK's ∂vec(P)/∂vec(F) with the stress S_geo in the geometric term:
// dP = dF·S_geo + F·(2μ dE + λ tr(dE) I), dE = ½(dFᵀF + FᵀdF), one column per unit dF.
elements::Mat<9> stvk_tangent(const Eigen::Matrix3d& F, const Eigen::Matrix3d& S_geo, const Lame& m) {
  const Eigen::Matrix3d I = Eigen::Matrix3d::Identity();
  elements::Mat<9> D;
  for (int c = 0; c < 9; ++c) {
    Eigen::Matrix3d dF = Eigen::Matrix3d::Zero();
    dF(c % 3, c / 3) = 1.0;
    const Eigen::Matrix3d dE = 0.5 * (dF.transpose() * F + F.transpose() * dF);
    const Eigen::Matrix3d dP = dF * S_geo + F * (2.0 * m.mu * dE + m.lambda * dE.trace() * I);
    D.col(c) = Eigen::Map<const elements::Vec<9>>(dP.data());
  }
  return D;
}

Eigen::Matrix3d stvk_stress(const Eigen::Matrix3d& F, const Lame& m) {
  const Eigen::Matrix3d I = Eigen::Matrix3d::Identity();
  const Eigen::Matrix3d E = 0.5 * (F.transpose() * F - I);
  return 2.0 * m.mu * E + m.lambda * E.trace() * I;
}

// The stable neo-Hookean tangent μI + λ' g gᵀ + s ∂²J/∂F² (s = λ'(J - α)) in the signed SVD's
// frame, dF = U E Vᵀ (an orthogonal change of basis of the 9 entries): J's second variation
// is Σ_{i<j} σ_k (E_ii E_jj - E_ij E_ji) (k the third index), so each off-diagonal pair
// (E_ij, E_ji) is an eigen-pair of its own, twist (1, -1)/√2 with μ + sσ_k and flip (1, 1)/√2
// with μ - sσ_k; g = diag(σ1σ2, σ0σ2, σ0σ1) and the rest stay in the 3×3 block of the
// diagonal entries. Clamps the negative eigenvalues and maps the result back; when none is
// negative, returns exact() (the tangent as piola_derivative forms it) instead.
template <class Exact>
elements::Mat<9> snh_tangent_psd(const Eigen::Matrix3d& F, const Lame& m, double lambda_p, double alpha, Exact exact) {
  const Eigen::JacobiSVD<Eigen::Matrix3d> svd(F, Eigen::ComputeFullU | Eigen::ComputeFullV);
  Eigen::Matrix3d U = svd.matrixU(), V = svd.matrixV();
  Eigen::Vector3d sigma = svd.singularValues();
  // rotations only: a reflection's sign goes to the smallest singular value
  if (U.determinant() < 0.0) {
    U.col(2) = -U.col(2);
    sigma[2] = -sigma[2];
  }
  if (V.determinant() < 0.0) {
    V.col(2) = -V.col(2);
    sigma[2] = -sigma[2];
  }
  const double s = lambda_p * (sigma.prod() - alpha);
  const Eigen::Vector3d c(sigma[1] * sigma[2], sigma[0] * sigma[2], sigma[0] * sigma[1]);
  Eigen::Matrix3d A = m.mu * Eigen::Matrix3d::Identity() + lambda_p * c * c.transpose();
  A(0, 1) += s * sigma[2];
  A(1, 0) += s * sigma[2];
  A(0, 2) += s * sigma[1];
  A(2, 0) += s * sigma[1];
  A(1, 2) += s * sigma[0];
  A(2, 1) += s * sigma[0];
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> block;
  block.computeDirect(A);
  const double lowest_pair = m.mu - std::abs(s) * sigma.cwiseAbs().maxCoeff();
  if (block.eigenvalues().minCoeff() >= 0.0 && lowest_pair >= 0.0) return exact();
  elements::Mat<9> D = elements::Mat<9>::Zero();
  const auto add = [&](double eigenvalue, const Eigen::Matrix3d& E) {
    if (eigenvalue <= 0.0) return;
    const Eigen::Matrix3d Q = U * E * V.transpose();
    const Eigen::Map<const elements::Vec<9>> q(Q.data());
    D.noalias() += eigenvalue * q * q.transpose();
  };
  for (int e = 0; e < 3; ++e) add(block.eigenvalues()[e], Eigen::Matrix3d(block.eigenvectors().col(e).asDiagonal()));
  const double r = std::sqrt(0.5);
  for (int k = 0; k < 3; ++k) {
    const int i = (k + 1) % 3, j = (k + 2) % 3;
    Eigen::Matrix3d twist = Eigen::Matrix3d::Zero(), flip = Eigen::Matrix3d::Zero();
    twist(i, j) = r;
    twist(j, i) = -r;
    flip(i, j) = r;
    flip(j, i) = r;
    add(m.mu + s * sigma[k], twist);
    add(m.mu - s * sigma[k], flip);
  }
  return D;
}

}  // namespace

elements::Mat<9> piola_derivative_psd(TetLaw law, const Eigen::Matrix3d& F, const Lame& m) {
  if (law == TetLaw::stvk) {
    const Eigen::Matrix3d S = stvk_stress(F, m);
    Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig;
    eig.computeDirect(S);
    if (eig.eigenvalues().minCoeff() >= 0.0) return stvk_tangent(F, S, m);
    const Eigen::Matrix3d S_plus =
        eig.eigenvectors() * eig.eigenvalues().cwiseMax(0.0).asDiagonal() * eig.eigenvectors().transpose();
    return stvk_tangent(F, S_plus, m);
  }
  const SnhParams p = snh(m);
  return snh_tangent_psd(F, m, p.lambda, p.alpha, [&] { return piola_derivative(law, F, m); });
}

elements::Mat<9> piola_derivative(TetLaw law, const Eigen::Matrix3d& F, const Lame& m) {
  elements::Mat<9> D;
  if (law == TetLaw::stvk) return stvk_tangent(F, stvk_stress(F, m), m);
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

namespace {

// V̄ Bᵀ D B with B = ∂vec(F)/∂x, without forming B: ∂F(a, b)/∂x_k,a' = δaa' G(k, b), G's rows
// the shape functions' gradients (row 0 minus the sum of Dm⁻¹'s rows), so the 3×3 block (k, m)
// is V̄ Σ_bd G(k, b) G(m, d) D_bd, D_bd D's 3×3 blocks. 756 multiply-adds against the dense
// product's 2268, and none of Eigen's GEMM set-up, which these sizes take: 12 % of the toy
// ball's Newton step went to the dense form.
Mat12 tet_hessian_from(const elements::Mat<9>& D, const TetRest& rest) {
  Eigen::Matrix<double, 4, 3> G;
  G.row(0) = -rest.Dm_inv.colwise().sum();
  G.bottomRows<3>() = rest.Dm_inv;
  std::array<Eigen::Matrix3d, 12> M;  // M[3m + b] = Σ_d G(m, d) D_bd
  for (int m = 0; m < 4; ++m)
    for (int b = 0; b < 3; ++b)
      M[static_cast<std::size_t>(3 * m + b)] =
          G(m, 0) * D.block<3, 3>(3 * b, 0) + G(m, 1) * D.block<3, 3>(3 * b, 3) + G(m, 2) * D.block<3, 3>(3 * b, 6);
  Mat12 H;
  for (int k = 0; k < 4; ++k)
    for (int m = 0; m < 4; ++m) {
      const auto* Mm = &M[static_cast<std::size_t>(3 * m)];
      H.block<3, 3>(3 * k, 3 * m) = rest.volume * (G(k, 0) * Mm[0] + G(k, 1) * Mm[1] + G(k, 2) * Mm[2]);
    }
  return 0.5 * (H + H.transpose());
}

}  // namespace

Mat12 tet_hessian(TetLaw law, const TetPositions& x, const TetRest& rest, const Lame& m) {
  return tet_hessian_from(piola_derivative(law, deformation_gradient(x, rest), m), rest);
}

Mat12 tet_hessian_psd(TetLaw law, const TetPositions& x, const TetRest& rest, const Lame& m) {
  return tet_hessian_from(piola_derivative_psd(law, deformation_gradient(x, rest), m), rest);
}

}  // namespace sewn::physics::solids
