// The single-precision copy of a supernodal factor and its triangular solves (float_factor.hpp).
//
// CHOLMOD's supernodal layout (cholmod_core.h): supernode k holds the columns super[k] ..
// super[k+1]-1 of L (nc of them) as one dense column-major block of nr rows, the rows' indices
// s[pi[k]] .. s[pi[k+1]-1], the first nc of them the supernode's own columns; the block starts
// at x[px[k]], leading dimension nr. The upper triangle of its first nc rows is unused.

#include "float_factor.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include "panel_solve.hpp"

namespace sewn::physics::solve::detail {

bool FloatSupernodalFactor::assign(const cholmod_factor& L) {
  const std::size_t ns = L.nsuper;
  const auto* super = static_cast<const int*>(L.super);
  const auto* pi = static_cast<const int*>(L.pi);
  const auto* px = static_cast<const int*>(L.px);
  const auto* s = static_cast<const int*>(L.s);
  const auto* x = static_cast<const double*>(L.x);
  const auto* perm = static_cast<const int*>(L.Perm);
  super_.assign(super, super + ns + 1);
  pi_.assign(pi, pi + ns + 1);
  px_.assign(px, px + ns + 1);
  s_.assign(s, s + pi[ns]);
  x_.resize(static_cast<std::size_t>(px[ns]));
  std::transform(x, x + px[ns], x_.begin(), [](double v) { return static_cast<float>(v); });
  perm_.resize(L.n);
  for (std::size_t k = 0; k < L.n; ++k) perm_[k] = perm ? perm[k] : static_cast<int>(k);
  y_.resize(L.n);
  std::size_t widest = 0;
  for (std::size_t k = 0; k < ns; ++k) widest = std::max(widest, pi_[k + 1] - pi_[k]);
  w_.resize(widest);
  float biggest = 0;
  for (const float v : x_) biggest = std::max(biggest, std::abs(v));
  if (!(biggest <= std::numeric_limits<float>::max())) return false;  // inf or NaN
  for (std::size_t k = 0; k < ns; ++k) {
    const std::size_t nc = static_cast<std::size_t>(super_[k + 1] - super_[k]), nr = pi_[k + 1] - pi_[k];
    for (std::size_t j = 0; j < nc; ++j)
      if (!(x_[px_[k] + j * nr + j] >= std::numeric_limits<float>::min())) return false;
  }
  return true;
}

void FloatSupernodalFactor::clear() {
  super_.clear();
  x_.clear();
  x_.shrink_to_fit();
}

void FloatSupernodalFactor::solve(std::span<const double> rhs, std::span<double> out) {
  const std::size_t n = perm_.size();
  const std::size_t ns = super_.size() - 1;
  double* __restrict y = y_.data();
  double* __restrict w = w_.data();
  for (std::size_t k = 0; k < n; ++k) y[k] = rhs[static_cast<std::size_t>(perm_[k])];
  // L y = y, supernode by supernode: the dense lower triangle on the block's first nc rows,
  // its rows below gathered into w and scattered back once.
  for (std::size_t k = 0; k < ns; ++k) {
    const auto c0 = static_cast<std::size_t>(super_[k]);
    const std::size_t nc = static_cast<std::size_t>(super_[k + 1]) - c0, nr = pi_[k + 1] - pi_[k];
    const int* rows = s_.data() + pi_[k];
    const float* blk = x_.data() + px_[k];
    std::copy_n(y + c0, nc, w);
    std::fill(w + nc, w + nr, 0.0);
    panel_forward(blk, nc, nr, w);
    std::copy_n(w, nc, y + c0);
    for (std::size_t i = nc; i < nr; ++i) y[rows[i]] += w[i];
  }
  // Lᵀ y = y, supernodes in reverse: each column's dot product with the rows below, gathered.
  for (std::size_t k = ns; k-- > 0;) {
    const auto c0 = static_cast<std::size_t>(super_[k]);
    const std::size_t nc = static_cast<std::size_t>(super_[k + 1]) - c0, nr = pi_[k + 1] - pi_[k];
    const int* rows = s_.data() + pi_[k];
    const float* blk = x_.data() + px_[k];
    std::copy_n(y + c0, nc, w);
    for (std::size_t i = nc; i < nr; ++i) w[i] = y[rows[i]];
    panel_backward(blk, nc, nr, w);
    std::copy_n(w, nc, y + c0);
  }
  for (std::size_t k = 0; k < n; ++k) out[static_cast<std::size_t>(perm_[k])] = y[k];
}

}  // namespace sewn::physics::solve::detail
