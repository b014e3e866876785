#include "sewn/physics/shells/morley_element.hpp"

#include <cmath>
#include <sstream>

#include <Eigen/Eigenvalues>
#include <Eigen/LU>

#include "sewn/physics/errors.hpp"
#include "sewn/physics/shells/hinge_element.hpp"
#include "plate_quadratic.hpp"

namespace sewn::physics::shells {

namespace {

// Edge i's hinge in hinge_element.hpp's order: corner i (face A is a cyclic turn of T, so its
// normal is T's), the edge's corners, the node across.
constexpr std::array<int, 4> hinge_columns(int i) { return {i, (i + 1) % 3, (i + 2) % 3, 3 + i}; }

HingePositions hinge_of(const MorleyPositions& x, int i) {
  HingePositions h;
  const auto cols = hinge_columns(i);
  for (int c = 0; c < 4; ++c) h.col(c) = x.col(cols[static_cast<std::size_t>(c)]);
  return h;
}

bool has_hinge(MorleyEdge k) { return k != MorleyEdge::own; }
// ∂Δs_i/∂ψ_i by kind
double psi_coefficient(MorleyEdge k) { return k == MorleyEdge::own ? 1.0 : (k == MorleyEdge::other ? -1.0 : 0.0); }

}  // namespace

MorleyRest morley_rest(const MorleyPositions& X, const std::array<MorleyEdge, 3>& kind, const PlateMaterial& m) {
  if (!std::isfinite(m.stiffness) || !(m.stiffness > 0.0) || !std::isfinite(m.poisson) || !(m.poisson > -1.0) ||
      !(m.poisson < 0.5)) {
    std::ostringstream s;
    s << "Morley bending: the plate stiffness must be > 0 and Poisson's ratio in (-1, 0.5), got D = " << m.stiffness
      << ", nu = " << m.poisson;
    throw InputError(s.str());
  }
  MorleyRest r;
  r.kind = kind;
  const detail::PlateQuadratic pq = detail::plate_quadratic(X.leftCols<3>(), m, "Morley bending");
  const double area = pq.area;
  const Eigen::Matrix3d& Q = pq.Q;
  Eigen::Matrix3d G;  // c = G Δs
  for (int mm = 0; mm < 3; ++mm)
    for (int i = 0; i < 3; ++i) {
      const double len = (X.col((i + 2) % 3) - X.col((i + 1) % 3)).norm();
      G(mm, i) = mm == i ? 0.0 : -2.0 * area / len;
    }
  r.stiffness = G.transpose() * Q * G;
  r.stiffness = 0.5 * (r.stiffness + r.stiffness.transpose()).eval();
  for (int i = 0; i < 3; ++i) {
    if (!has_hinge(kind[static_cast<std::size_t>(i)])) continue;
    const HingePositions h = hinge_of(X, i);
    try {
      (void)hinge_rest(h);
    } catch (const InputError& e) {
      throw InputError("Morley bending: the hinge across edge " + std::to_string(i) + ": " + e.what());
    }
    r.theta[static_cast<std::size_t>(i)] = dihedral_angle(h);
  }
  return r;
}

Eigen::Vector3d morley_slopes(const MorleyPositions& x, const Eigen::Vector3d& psi, const MorleyRest& rest) {
  Eigen::Vector3d ds;
  for (int i = 0; i < 3; ++i) {
    const MorleyEdge k = rest.kind[static_cast<std::size_t>(i)];
    ds[i] = psi_coefficient(k) * psi[i];
    if (has_hinge(k)) ds[i] -= wrap_angle(dihedral_angle(hinge_of(x, i)) - rest.theta[static_cast<std::size_t>(i)]);
  }
  return ds;
}

double morley_energy(const MorleyPositions& x, const Eigen::Vector3d& psi, const MorleyRest& rest) {
  const Eigen::Vector3d ds = morley_slopes(x, psi, rest);
  return 0.5 * ds.dot(rest.stiffness * ds);
}

namespace {

// J = ∂Δs/∂(x, ψ) (3×21), optionally with Σ_i w_i ∂²Δs_i added into H.
Eigen::Matrix<double, 3, 21> slope_jacobian(const MorleyPositions& x, const MorleyRest& rest, const Eigen::Vector3d* w,
                                            MorleyMat* H) {
  Eigen::Matrix<double, 3, 21> J = Eigen::Matrix<double, 3, 21>::Zero();
  for (int i = 0; i < 3; ++i) {
    const MorleyEdge k = rest.kind[static_cast<std::size_t>(i)];
    J(i, 18 + i) = psi_coefficient(k);
    if (!has_hinge(k)) continue;
    const HingePositions h = hinge_of(x, i);
    const auto cols = hinge_columns(i);
    const Vec12 g = -dihedral_gradient(h);
    for (int a = 0; a < 4; ++a) J.row(i).segment<3>(3 * cols[static_cast<std::size_t>(a)]) += g.segment<3>(3 * a).transpose();
    if (H == nullptr) continue;
    const Mat12 hk = dihedral_hessian(h) * (-(*w)[i]);
    for (int a = 0; a < 4; ++a)
      for (int b = 0; b < 4; ++b)
        H->block<3, 3>(3 * cols[static_cast<std::size_t>(a)], 3 * cols[static_cast<std::size_t>(b)]) += hk.block<3, 3>(3 * a, 3 * b);
  }
  return J;
}

}  // namespace

MorleyVec morley_gradient(const MorleyPositions& x, const Eigen::Vector3d& psi, const MorleyRest& rest) {
  const Eigen::Vector3d Sds = rest.stiffness * morley_slopes(x, psi, rest);
  return slope_jacobian(x, rest, nullptr, nullptr).transpose() * Sds;
}

MorleyMat morley_hessian(const MorleyPositions& x, const Eigen::Vector3d& psi, const MorleyRest& rest) {
  const Eigen::Vector3d Sds = rest.stiffness * morley_slopes(x, psi, rest);
  MorleyMat H = MorleyMat::Zero();
  const Eigen::Matrix<double, 3, 21> J = slope_jacobian(x, rest, &Sds, &H);
  H += J.transpose() * rest.stiffness * J;
  return 0.5 * (H + H.transpose());
}

}  // namespace sewn::physics::shells
