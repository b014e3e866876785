#include "sewn/physics/shells/patch_element.hpp"

#include <algorithm>
#include <cmath>
#include <sstream>

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>
#include <Eigen/Geometry>
#include <Eigen/LU>

#include "sewn/physics/errors.hpp"
#include "sewn/physics/shells/hinge_element.hpp"
#include "sewn/physics/shells/material_check.hpp"
#include "plate_quadratic.hpp"

namespace sewn::physics::shells {

namespace {

// Neighbour k's hinge in hinge_element.hpp's order: T's corner opposite the edge (face A is then
// a cyclic turn of T, so its normal is T's), the edge's two corners, the neighbour's node.
template <int N>
std::array<int, 4> hinge_columns(const PatchRest& rest, int k) {
  const int i = rest.edge[static_cast<std::size_t>(k)];
  return {i, (i + 1) % 3, (i + 2) % 3, 3 + k};
}

template <int N>
HingePositions hinge_of(const PatchPositions<N>& x, const std::array<int, 4>& cols) {
  HingePositions h;
  for (int c = 0; c < 4; ++c) h.col(c) = x.col(cols[static_cast<std::size_t>(c)]);
  return h;
}

// d_k = ℓ_k (θ_k - θ̄_k): to first order the neighbour's height above T's plane (up to one sign
// shared by all k, which the quadratic energy does not see).
template <int N>
Eigen::Vector3d heights(const PatchPositions<N>& x, const PatchRest& rest) {
  Eigen::Vector3d d = Eigen::Vector3d::Zero();
  for (int k = 0; k < rest.count; ++k) {
    const auto kk = static_cast<std::size_t>(k);
    d[k] = rest.lever[kk] * wrap_angle(dihedral_angle(hinge_of<N>(x, hinge_columns<N>(rest, k))) - rest.theta[kk]);
  }
  return d;
}

std::string describe(const std::array<std::uint8_t, 3>& edges, int count) {
  std::ostringstream s;
  for (int k = 0; k < count; ++k) s << (k ? ", " : "") << int{edges[static_cast<std::size_t>(k)]};
  return s.str();
}

}  // namespace

PlateMaterial plate_material(double young, double poisson, double thickness) {
  check_shell_material("patch bending", young, poisson, thickness);
  return {young * thickness * thickness * thickness / (12.0 * (1.0 - poisson * poisson)), poisson};
}

template <int N>
PatchRest patch_rest(const PatchPositions<N>& X, const std::array<std::uint8_t, N - 3>& edges,
                     const std::array<std::uint8_t, N - 3>& clamped, const PlateMaterial& m) {
  constexpr int K = N - 3;
  PatchRest r;
  r.count = K;
  for (int k = 0; k < K; ++k) {
    r.edge[static_cast<std::size_t>(k)] = edges[static_cast<std::size_t>(k)];
    r.clamped[static_cast<std::size_t>(k)] = clamped[static_cast<std::size_t>(k)] != 0 ? 1 : 0;
  }
  for (int k = 0; k < K; ++k)
    for (int j = 0; j < k; ++j)
      if (edges[static_cast<std::size_t>(k)] > 2 || edges[static_cast<std::size_t>(k)] == edges[static_cast<std::size_t>(j)])
        throw InputError("patch bending: neighbour edges " + describe(r.edge, K) + " must be distinct corners 0, 1, 2");
  if (edges[0] > 2) throw InputError("patch bending: neighbour edges " + describe(r.edge, K) + " must be corners 0, 1, 2");
  const detail::PlateQuadratic pq = detail::plate_quadratic(X.template leftCols<3>(), m, "patch bending");
  const auto& p = pq.corners;
  const auto& grad = pq.grad;
  const Eigen::Matrix3d& Q = pq.Q;
  auto bary = [&](const Eigen::Vector2d& q) {
    const Eigen::Vector2d l = pq.Dm_inv * (q - p.col(0));
    return Eigen::Vector3d(1.0 - l[0] - l[1], l[0], l[1]);
  };
  // each neighbour unfolded into T's plane across its edge: its lever ℓ and bubble values
  Eigen::Matrix<double, K, 3> C;
  for (int k = 0; k < K; ++k) {
    const auto kk = static_cast<std::size_t>(k);
    const auto cols = hinge_columns<N>(r, k);
    const HingePositions h = hinge_of<N>(X, cols);
    const Eigen::Vector3d P = h.col(1), ehat = (h.col(2) - h.col(1)).normalized();
    const double s = (h.col(3) - P).dot(ehat);
    const double lever = ((h.col(3) - P) - s * ehat).norm();
    const double edge_len = (h.col(2) - h.col(1)).norm();
    if (!std::isfinite(lever) || !(lever > 1e-6 * edge_len)) {
      std::ostringstream msg;
      msg << "patch bending: the neighbour across edge " << cols[0] << " lies on the edge's line (distance " << lever << " m)";
      throw InputError(msg.str());
    }
    const Eigen::Vector2d pP = p.col(cols[1]), e2d = (p.col(cols[2]) - pP).normalized();
    Eigen::Vector2d t(e2d.y(), -e2d.x());
    if (t.dot(p.col(cols[0]) - pP) > 0.0) t = -t;  // away from T
    if (r.clamped[kk] != 0) {
      // the bubbles' outward slope at the edge's midpoint, where λ = ½ on the edge's corners
      for (int mm = 0; mm < 3; ++mm) {
        const auto bary_mid = [&](int a) { return a == cols[0] ? 0.0 : 0.5; };
        const int a = (mm + 1) % 3, b = (mm + 2) % 3;
        C(k, mm) = t.dot(bary_mid(a) * grad.col(b) + bary_mid(b) * grad.col(a));
      }
      r.lever[kk] = 1.0;
    } else {
      const Eigen::Vector3d l = bary(pP + s * e2d + lever * t);
      for (int mm = 0; mm < 3; ++mm) C(k, mm) = l[(mm + 1) % 3] * l[(mm + 2) % 3];
      r.lever[kk] = lever;
    }
    r.theta[kk] = dihedral_angle(h);
  }
  // E = min_β ½βᵀQβ subject to Cβ = d  =  ½ dᵀ (C Q⁻¹ Cᵀ)⁻¹ d
  const Eigen::Matrix<double, K, K> M = C * Q.ldlt().solve(C.transpose());
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix<double, K, K>> eig(M);
  const double lo = eig.eigenvalues().minCoeff(), hi = eig.eigenvalues().maxCoeff();
  if (!std::isfinite(lo + hi) || !(lo > 1e-10 * hi)) {
    std::ostringstream s;
    s << "patch bending: the triangle and its neighbours across edges " << describe(r.edge, K)
      << " lie on a conic, so no single quadratic fits them (condition " << lo / hi << ")";
    throw InputError(s.str());
  }
  const Eigen::Matrix<double, K, K> S = eig.eigenvectors() * eig.eigenvalues().cwiseInverse().asDiagonal() *
                                        eig.eigenvectors().transpose();
  r.stiffness.template topLeftCorner<K, K>() = 0.5 * (S + S.transpose());
  return r;
}

template <int N>
double patch_energy(const PatchPositions<N>& x, const PatchRest& rest) {
  const Eigen::Vector3d d = heights<N>(x, rest);
  return 0.5 * d.dot(rest.stiffness * d);
}

namespace {

// Σ_k (S d)_k ℓ_k ∇θ_k: the gradient of ½ dᵀ S d given S d.
template <int N>
elements::Vec<3 * N> gradient_with(const PatchPositions<N>& x, const PatchRest& rest, const Eigen::Vector3d& Sd) {
  elements::Vec<3 * N> g = elements::Vec<3 * N>::Zero();
  for (int k = 0; k < rest.count; ++k) {
    const auto cols = hinge_columns<N>(rest, k);
    const Vec12 gk = dihedral_gradient(hinge_of<N>(x, cols)) * (Sd[k] * rest.lever[static_cast<std::size_t>(k)]);
    for (int c = 0; c < 4; ++c) g.template segment<3>(3 * cols[static_cast<std::size_t>(c)]) += gk.segment<3>(3 * c);
  }
  return g;
}

}  // namespace

template <int N>
elements::Vec<3 * N> patch_gradient(const PatchPositions<N>& x, const PatchRest& rest) {
  return gradient_with<N>(x, rest, rest.stiffness * heights<N>(x, rest));
}

template <int N>
double patch_energy_gradient(const PatchPositions<N>& x, const PatchRest& rest, elements::Vec<3 * N>& g) {
  const Eigen::Vector3d d = heights<N>(x, rest);
  const Eigen::Vector3d Sd = rest.stiffness * d;
  g = gradient_with<N>(x, rest, Sd);
  return 0.5 * d.dot(Sd);
}

namespace {

// Scatters a hinge's 12 entries (row vector) into a 3N row at the hinge's columns.
template <int N>
void scatter_row(Eigen::Matrix<double, 3, 3 * N>& J, int k, const std::array<int, 4>& cols, const Vec12& gk) {
  for (int a = 0; a < 4; ++a) J.row(k).template segment<3>(3 * cols[static_cast<std::size_t>(a)]) += gk.segment<3>(3 * a).transpose();
}

}  // namespace

namespace {

// H = Jᵀ S J + Σ_k (S d)_k ℓ_k ∇²θ_k, J's row k = ∂d_k/∂x = ℓ_k ∇θ_k, with hinge k's ∇θ_k and
// ∇²θ_k from derivatives(k) = {g, H, cols}: the 12 entries of g and the 12×12 of H stand for the
// patch columns cols (its hinge's in this patch's order, or reversed).
template <int N, class Derivatives>
elements::Mat<3 * N> hessian_from(const PatchPositions<N>& x, const PatchRest& rest, Derivatives&& derivatives) {
  const Eigen::Vector3d Sd = rest.stiffness * heights<N>(x, rest);
  Eigen::Matrix<double, 3, 3 * N> J = Eigen::Matrix<double, 3, 3 * N>::Zero();
  elements::Mat<3 * N> H = elements::Mat<3 * N>::Zero();
  for (int k = 0; k < rest.count; ++k) {
    const double lever = rest.lever[static_cast<std::size_t>(k)];
    const auto [gk, hk, cols] = derivatives(k);
    scatter_row<N>(J, k, cols, gk * lever);
    const double c = Sd[k] * lever;
    for (int a = 0; a < 4; ++a) {
      const int A = cols[static_cast<std::size_t>(a)];
      for (int b = 0; b < 4; ++b) H.template block<3, 3>(3 * A, 3 * cols[static_cast<std::size_t>(b)]) += c * hk.template block<3, 3>(3 * a, 3 * b);
    }
  }
  // coefficient-wise products: Eigen's blocked GEMM costs more than the ~1k flops at this size
  const Eigen::Matrix<double, 3, 3 * N> SJ = rest.stiffness.lazyProduct(J);
  H.noalias() += J.transpose().lazyProduct(SJ);
  return 0.5 * (H + H.transpose());
}

struct HingeTerms {
  const Vec12& g;
  const Mat12& H;
  std::array<int, 4> cols;
};

}  // namespace

template <int N>
elements::Mat<3 * N> patch_hessian(const PatchPositions<N>& x, const PatchRest& rest) {
  Vec12 gk;
  Mat12 hk;
  return hessian_from<N>(x, rest, [&](int k) {
    const auto cols = hinge_columns<N>(rest, k);
    dihedral_derivatives(hinge_of<N>(x, cols), gk, hk);
    return HingeTerms{gk, hk, cols};
  });
}

template <int N>
elements::Mat<3 * N> patch_hessian_shared(const PatchPositions<N>& x, const PatchRest& rest, const SharedHinges& hinges) {
  return hessian_from<N>(x, rest, [&](int k) {
    const auto kk = static_cast<std::size_t>(k);
    auto cols = hinge_columns<N>(rest, k);
    if (hinges.reversed[kk]) std::reverse(cols.begin(), cols.end());
    return HingeTerms{hinges.of[kk]->g, hinges.of[kk]->H, cols};
  });
}

template <int N>
elements::Mat<3 * N> patch_hessian_gauss_newton(const PatchPositions<N>& x, const PatchRest& rest) {
  Eigen::Matrix<double, 3, 3 * N> J = Eigen::Matrix<double, 3, 3 * N>::Zero();
  for (int k = 0; k < rest.count; ++k) {
    const auto cols = hinge_columns<N>(rest, k);
    scatter_row<N>(J, k, cols, dihedral_gradient(hinge_of<N>(x, cols)) * rest.lever[static_cast<std::size_t>(k)]);
  }
  // S is symmetric positive definite (patch_rest refuses an ill-conditioned one), so JᵀSJ is PSD.
  // Coefficient by coefficient over J's 3 rows, one triangle mirrored (exactly symmetric): Eigen's
  // blocked product for the 18×18 was a third of this function's time.
  const Eigen::Matrix<double, 3, 3 * N> SJ = rest.stiffness * J;
  elements::Mat<3 * N> H;
  for (int j = 0; j < 3 * N; ++j)
    for (int i = j; i < 3 * N; ++i) H(i, j) = H(j, i) = J(0, i) * SJ(0, j) + J(1, i) * SJ(1, j) + J(2, i) * SJ(2, j);
  return H;
}

#define SEWN_PATCH_INSTANTIATE(N)                                                                                       \
  template PatchRest patch_rest<N>(const PatchPositions<N>&, const std::array<std::uint8_t, N - 3>&,                  \
                                   const std::array<std::uint8_t, N - 3>&, const PlateMaterial&);                     \
  template double patch_energy<N>(const PatchPositions<N>&, const PatchRest&);                                         \
  template elements::Vec<3 * N> patch_gradient<N>(const PatchPositions<N>&, const PatchRest&);                          \
  template double patch_energy_gradient<N>(const PatchPositions<N>&, const PatchRest&, elements::Vec<3 * N>&);          \
  template elements::Mat<3 * N> patch_hessian<N>(const PatchPositions<N>&, const PatchRest&);                         \
  template elements::Mat<3 * N> patch_hessian_shared<N>(const PatchPositions<N>&, const PatchRest&, const SharedHinges&); \
  template elements::Mat<3 * N> patch_hessian_gauss_newton<N>(const PatchPositions<N>&, const PatchRest&);
SEWN_PATCH_INSTANTIATE(4)
SEWN_PATCH_INSTANTIATE(5)
SEWN_PATCH_INSTANTIATE(6)
#undef SEWN_PATCH_INSTANTIATE

}  // namespace sewn::physics::shells
