#include "sewn/physics/cg.hpp"

#include <cmath>

#include <Eigen/LU>

namespace sewn::physics {

namespace {

// Eight independent partial sums: a single running sum is bound by the add latency, and
// the compiler may not reorder it itself (no -ffast-math). Fixed order: deterministic.
double dot(std::span<const double> a, std::span<const double> b) {
  double part[8] = {};
  const std::size_t n = a.size(), n8 = n - n % 8;
  const double* __restrict x = a.data();
  const double* __restrict y = b.data();
  for (std::size_t k = 0; k < n8; k += 8)
    for (std::size_t q = 0; q < 8; ++q) part[q] += x[k + q] * y[k + q];
  double s = ((part[0] + part[1]) + (part[2] + part[3])) + ((part[4] + part[5]) + (part[6] + part[7]));
  for (std::size_t k = n8; k < n; ++k) s += x[k] * y[k];
  return s;
}

void apply_precond(std::span<const double> P, std::span<const double> r, std::span<const double> free_dof,
                   std::span<double> z) {
  const std::size_t n = r.size() / 3;
  for (std::size_t i = 0; i < n; ++i) {
    const double* B = P.data() + 9 * i;
    const double r0 = r[3 * i], r1 = r[3 * i + 1], r2 = r[3 * i + 2];
    z[3 * i] = free_dof[3 * i] * (B[0] * r0 + B[3] * r1 + B[6] * r2);
    z[3 * i + 1] = free_dof[3 * i + 1] * (B[1] * r0 + B[4] * r1 + B[7] * r2);
    z[3 * i + 2] = free_dof[3 * i + 2] * (B[2] * r0 + B[5] * r1 + B[8] * r2);
  }
}

}  // namespace

void CgWorkspace::resize(std::size_t n3) {
  r.resize(n3);
  z.resize(n3);
  p.resize(n3);
  q.resize(n3);
}

void block_jacobi_inverse(const BlockMatrix& A, std::span<const double> free_dof, std::span<double> inverse) {
  for (Index i = 0; i < A.size(); ++i) {
    Eigen::Matrix3d B = A.block(A.diagonal(i));
    for (int a = 0; a < 3; ++a) {
      if (free_dof[3 * i + a] != 0.0) continue;
      B.row(a).setZero();
      B.col(a).setZero();
      B(a, a) = 1.0;
    }
    Eigen::Matrix3d inv;
    bool invertible = false;
    double det = 0;
    B.computeInverseAndDetWithCheck(inv, det, invertible, 0.0);
    if (!invertible || !inv.allFinite()) {
      // Singular block (a node no term stiffens and without mass): fall back to Jacobi.
      inv.setZero();
      for (int a = 0; a < 3; ++a) inv(a, a) = B(a, a) != 0.0 ? 1.0 / B(a, a) : 1.0;
    }
    Eigen::Map<Eigen::Matrix3d>(inverse.data() + 9 * std::size_t{i}) = inv;
  }
}

CgResult filtered_pcg(const BlockMatrix& A, std::span<const double> b, std::span<double> x,
                      std::span<const double> free_dof, std::span<const double> P, double tolerance,
                      int max_iterations, CgWorkspace& ws) {
  const std::size_t n3 = b.size();
  ws.resize(n3);
  std::span<double> r(ws.r), z(ws.z), p(ws.p), q(ws.q);
  CgResult out;
  double b_norm2 = 0;
  for (std::size_t k = 0; k < n3; ++k) b_norm2 += free_dof[k] * b[k] * b[k];
  if (b_norm2 == 0.0) {
    // Zero right-hand side: the free part of the solution is zero.
    for (std::size_t k = 0; k < n3; ++k)
      if (free_dof[k] != 0.0) x[k] = 0.0;
    out.converged = true;
    return out;
  }
  const double b_norm = std::sqrt(b_norm2);
  A.multiply(x, q);
  for (std::size_t k = 0; k < n3; ++k) r[k] = free_dof[k] * (b[k] - q[k]);
  double r_norm = std::sqrt(dot(r, r));
  apply_precond(P, r, free_dof, z);
  for (std::size_t k = 0; k < n3; ++k) p[k] = z[k];
  double rz = dot(r, z);
  int it = 0;
  while (r_norm > tolerance * b_norm && it < max_iterations) {
    A.multiply(p, q);
    for (std::size_t k = 0; k < n3; ++k) q[k] *= free_dof[k];
    const double pq = dot(p, q);
    if (!(pq > 0.0)) {
      out.breakdown = true;
      break;
    }
    const double alpha = rz / pq;
    for (std::size_t k = 0; k < n3; ++k) {
      x[k] += alpha * p[k];
      r[k] -= alpha * q[k];
    }
    ++it;
    r_norm = std::sqrt(dot(r, r));
    apply_precond(P, r, free_dof, z);
    const double rz_new = dot(r, z);
    const double beta = rz_new / rz;
    rz = rz_new;
    for (std::size_t k = 0; k < n3; ++k) p[k] = z[k] + beta * p[k];
  }
  out.iterations = it;
  out.relative_residual = r_norm / b_norm;
  out.converged = !out.breakdown && std::isfinite(r_norm) && r_norm <= tolerance * b_norm;
  return out;
}

}  // namespace sewn::physics
