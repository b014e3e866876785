#include "sewn/physics/block_matrix.hpp"

#include <algorithm>
#include <atomic>
#include <string>

#include "sewn/physics/errors.hpp"
#include "parallel/ranges.hpp"

#if defined(__AVX512F__) && defined(__AVX512VL__)
#include <immintrin.h>
#define SEWN_BLOCK_AVX512 1
#endif

namespace sewn::physics {

void BlockMatrix::build_pattern(Index n, std::span<const NodePair> pairs) {
  for (const NodePair& p : pairs) {
    if (p.i >= n || p.j >= n || p.i == p.j)
      throw InputError("BlockMatrix::build_pattern: bad node pair (" + std::to_string(p.i) + ", " +
                       std::to_string(p.j) + ") for " + std::to_string(n) + " nodes");
  }
  // Count per row (with duplicates), fill, then sort and unique each row in place.
  std::vector<Index> count(std::size_t{n} + 1, 1);  // the diagonal
  for (const NodePair& p : pairs) {
    ++count[p.i];
    ++count[p.j];
  }
  std::vector<Index> start(std::size_t{n} + 1, 0);
  for (Index i = 0; i < n; ++i) start[i + 1] = start[i] + count[i];
  std::vector<Index> cols(start[n]);
  std::vector<Index> fill(start.begin(), start.end() - 1);
  for (Index i = 0; i < n; ++i) cols[fill[i]++] = i;
  for (const NodePair& p : pairs) {
    cols[fill[p.i]++] = p.j;
    cols[fill[p.j]++] = p.i;
  }
  n_ = n;
  row_.assign(std::size_t{n} + 1, 0);
  col_.clear();
  col_.reserve(cols.size());
  diag_.assign(n, 0);
  for (Index i = 0; i < n; ++i) {
    auto first = cols.begin() + start[i];
    auto last = cols.begin() + start[i + 1];
    std::sort(first, last);
    last = std::unique(first, last);
    for (auto it = first; it != last; ++it) {
      if (*it == i) diag_[i] = static_cast<Index>(col_.size());
      col_.push_back(*it);
    }
    row_[i + 1] = static_cast<Index>(col_.size());
  }
  val_.assign(9 * col_.size(), 0.0);
  // Unique across matrices, so that a solver caching an analysis per pattern cannot mistake
  // another matrix's pattern for the one it analysed.
  static std::atomic<std::uint64_t> patterns{0};
  version_ = ++patterns;
}

Index BlockMatrix::find(Index i, Index j) const {
  if (i >= n_ || j >= n_) return invalid_index;
  const auto first = col_.begin() + row_[i];
  const auto last = col_.begin() + row_[i + 1];
  const auto it = std::lower_bound(first, last, j);
  return (it != last && *it == j) ? static_cast<Index>(it - col_.begin()) : invalid_index;
}

void BlockMatrix::set_zero() {
  if (row_.empty()) return;  // no pattern built
  // Split by rows as multiply() is: on a large model (32³: 70 MB) one thread's memset was the
  // implicit step's largest serial part (docs/solvers.md, Threads).
  const int parts = detail::parts_for(n_, multiply_grain);
  detail::run_parts(parts, [&](int t) {
    const std::size_t b0 = row_[detail::range_begin(n_, parts, t)], b1 = row_[detail::range_begin(n_, parts, t + 1)];
    std::fill(val_.begin() + static_cast<std::ptrdiff_t>(9 * b0), val_.begin() + static_cast<std::ptrdiff_t>(9 * b1), 0.0);
  });
}

void BlockMatrix::multiply(std::span<const double> x, std::span<double> y) const {
  // Rows are independent: each thread computes whole rows, the same way as one thread would.
  const int parts = detail::parts_for(n_, multiply_grain);
  detail::run_parts(parts, [&](int t) {
    multiply_rows(x, y, static_cast<Index>(detail::range_begin(n_, parts, t)),
                  static_cast<Index>(detail::range_begin(n_, parts, t + 1)));
  });
}

void BlockMatrix::multiply_rows(std::span<const double> x, std::span<double> y, Index first, Index last) const {
  const double* __restrict xv = x.data();
  double* __restrict yv = y.data();
  const double* __restrict val = val_.data();
#ifdef SEWN_BLOCK_AVX512
  // A block's columns are 3 contiguous doubles: one masked 256-bit load each, times a
  // broadcast of x; three accumulators keep the FMA chains independent.
  constexpr __mmask8 xyz = 0x7;
  for (Index i = first; i < last; ++i) {
    __m256d a0 = _mm256_setzero_pd(), a1 = _mm256_setzero_pd(), a2 = _mm256_setzero_pd();
    for (Index k = row_[i]; k < row_[i + 1]; ++k) {
      const double* b = val + 9 * std::size_t{k};
      const double* xc = xv + 3 * std::size_t{col_[k]};
      a0 = _mm256_fmadd_pd(_mm256_maskz_loadu_pd(xyz, b), _mm256_broadcast_sd(xc), a0);
      a1 = _mm256_fmadd_pd(_mm256_maskz_loadu_pd(xyz, b + 3), _mm256_broadcast_sd(xc + 1), a1);
      a2 = _mm256_fmadd_pd(_mm256_maskz_loadu_pd(xyz, b + 6), _mm256_broadcast_sd(xc + 2), a2);
    }
    _mm256_mask_storeu_pd(yv + 3 * std::size_t{i}, xyz, _mm256_add_pd(_mm256_add_pd(a0, a1), a2));
  }
#else
  for (Index i = first; i < last; ++i) {
    double y0 = 0, y1 = 0, y2 = 0;
    for (Index k = row_[i]; k < row_[i + 1]; ++k) {
      const double* b = val + 9 * std::size_t{k};
      const double* xc = xv + 3 * std::size_t{col_[k]};
      y0 += b[0] * xc[0] + b[3] * xc[1] + b[6] * xc[2];
      y1 += b[1] * xc[0] + b[4] * xc[1] + b[7] * xc[2];
      y2 += b[2] * xc[0] + b[5] * xc[1] + b[8] * xc[2];
    }
    yv[3 * i] = y0;
    yv[3 * i + 1] = y1;
    yv[3 * i + 2] = y2;
  }
#endif
}

Eigen::SparseMatrix<double> BlockMatrix::to_sparse() const {
  std::vector<Eigen::Triplet<double>> t;
  t.reserve(val_.size());
  for (Index i = 0; i < n_; ++i)
    for (Index k = row_[i]; k < row_[i + 1]; ++k)
      for (int c = 0; c < 3; ++c)
        for (int r = 0; r < 3; ++r)
          t.emplace_back(3 * i + r, 3 * col_[k] + c, val_[9 * std::size_t{k} + 3 * c + r]);
  Eigen::SparseMatrix<double> s(3 * Eigen::Index{n_}, 3 * Eigen::Index{n_});
  s.setFromTriplets(t.begin(), t.end());
  return s;
}

}  // namespace sewn::physics
