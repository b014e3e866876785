// The CG loop of the kept-preconditioner backends (kept_pcg.hpp).

#include "kept_pcg.hpp"

#include <algorithm>
#include <cmath>

#include "../dot8.hpp"

namespace sewn::physics::solve::detail {

namespace {

using physics::detail::dot8;

// |S b| over the free axes (S the free-axis mask).
double free_norm(std::span<const double> b, std::span<const double> free_dof) {
  double bb = 0;
  for (std::size_t k = 0; k < b.size(); ++k) bb += free_dof[k] * b[k] * b[k];
  return std::sqrt(bb);
}

// A zero right-hand side: the free axes' solution is zero, the fixed axes keep their values.
PcgOutcome zero_solution(std::span<double> x, std::span<const double> free_dof) {
  for (std::size_t k = 0; k < x.size(); ++k)
    if (free_dof[k] != 0.0) x[k] = 0.0;
  PcgOutcome out;
  out.converged = true;
  return out;
}

// The preconditioned CG iterations both layouts share, from the first residual on: `product`
// sets q = S A p and returns p . q, `apply` sets z from r (masked), each on n entries.
template <class Product, class Apply>
void cg_iterate(std::size_t n, double* x, double* r, double* z, double* p, const double* q, double stop,
                int max_iterations, Product&& product, Apply&& apply, PcgOutcome& out) {
  double r_norm = std::sqrt(dot8(r, r, n));
  if (r_norm > stop) apply();
  else std::fill(z, z + n, 0.0);
  std::copy(z, z + n, p);
  double rz = dot8(r, z, n);
  int it = 0;
  while (r_norm > stop && it < max_iterations) {
    const double pq = product();
    if (!(pq > 0.0) || !(rz > 0.0)) {
      out.breakdown = true;
      break;
    }
    const double alpha = rz / pq;
    for (std::size_t k = 0; k < n; ++k) {
      x[k] += alpha * p[k];
      r[k] -= alpha * q[k];
    }
    ++it;
    r_norm = std::sqrt(dot8(r, r, n));
    if (r_norm <= stop) break;
    apply();
    const double rz_new = dot8(r, z, n);
    const double beta = rz_new / rz;
    rz = rz_new;
    for (std::size_t k = 0; k < n; ++k) p[k] = z[k] + beta * p[k];
  }
  out.iterations = it;
  out.residual = r_norm;
  out.converged = std::isfinite(r_norm) && r_norm <= stop;
}

}  // namespace

PcgOutcome pcg_with(const BlockMatrix& A, std::span<const double> b, std::span<double> x, std::span<const double> free_dof,
                    double tolerance, double floor, int max_iterations,
                    const std::function<void(std::span<const double>, std::span<double>)>& precondition, PcgWorkspace& ws) {
  const std::size_t n3 = b.size();
  for (auto* v : {&ws.r, &ws.z, &ws.p, &ws.q}) v->resize(n3);
  auto &r = ws.r, &z = ws.z, &p = ws.p, &q = ws.q;
  PcgOutcome out;
  const double b_norm = free_norm(b, free_dof);
  if (b_norm == 0.0) return zero_solution(x, free_dof);
  const double stop = std::max(tolerance * b_norm, floor);
  A.multiply(x, q);
  for (std::size_t k = 0; k < n3; ++k) r[k] = free_dof[k] * (b[k] - q[k]);
  auto product = [&] {
    A.multiply(p, q);
    for (std::size_t k = 0; k < n3; ++k) q[k] *= free_dof[k];
    return dot8(p.data(), q.data(), n3);
  };
  auto apply = [&] {
    precondition(r, z);
    for (std::size_t k = 0; k < n3; ++k) z[k] *= free_dof[k];
  };
  cg_iterate(n3, x.data(), r.data(), z.data(), p.data(), q.data(), stop, max_iterations, product, apply, out);
  out.relative_residual = out.residual / b_norm;
  return out;
}

PcgOutcome pcg_padded(FineLevel& fine, std::span<const double> b, std::span<double> x, std::span<const double> free_dof,
                      double tolerance, double floor, int max_iterations,
                      const std::function<void(const double*, double*)>& precondition, PcgWorkspace& ws) {
  const std::size_t n4 = 4 * fine.nodes();
  PcgOutcome out;
  const double b_norm = free_norm(b, free_dof);
  if (b_norm == 0.0) return zero_solution(x, free_dof);
  for (auto* v : {&ws.r, &ws.z, &ws.p, &ws.q, &ws.x}) v->resize(n4);
  double* __restrict r = ws.r.data();
  double* __restrict z = ws.z.data();
  double* __restrict p = ws.p.data();
  double* __restrict q = ws.q.data();
  double* __restrict xv = ws.x.data();
  const double* __restrict f = fine.free4();
  const double stop = std::max(tolerance * b_norm, floor);
  FineLevel::pad(x, xv);
  FineLevel::pad(b, r);
  fine.product(xv, q);  // S A x, x holding the prescribed values on the fixed axes
  for (std::size_t k = 0; k < n4; ++k) r[k] = f[k] * r[k] - q[k];
  auto product = [&] { return fine.product(p, q); };
  auto apply = [&] {
    precondition(r, z);
    for (std::size_t k = 0; k < n4; ++k) z[k] *= f[k];
  };
  cg_iterate(n4, xv, r, z, p, q, stop, max_iterations, product, apply, out);
  FineLevel::unpad(xv, x);
  out.relative_residual = out.residual / b_norm;
  return out;
}

}  // namespace sewn::physics::solve::detail
