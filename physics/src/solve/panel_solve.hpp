// Internal: the triangular solves on one dense supernodal panel, whatever precision it is stored
// in (the arithmetic is double): BlockCholesky's solves and the float copy of CHOLMOD's factor.
//
// A panel holds nc columns of L as nr rows, column-major (leading dimension nr), the first nc
// rows its own pivots (lower triangle; the upper one is not read), the others the rows below.
//
// Both sweeps take the columns four at a time below their 4×4 triangle: one pass over w for four
// columns instead of four (forward: a load and a store of w[i] per four multiply-adds; backward:
// four dot products sharing each load of w). On the 8×8×10 beam's factor (a dense 477-wide last
// panel) the column-at-a-time sweeps were about half of a preconditioner application.
#pragma once

#include <cstddef>
#include <type_traits>

#if defined(__AVX__)
#include <immintrin.h>
#endif

#include "../dot8.hpp"

namespace sewn::physics::solve::detail {

namespace panel_lanes {

// Four and eight lanes of double, and N values of a panel read unaligned through its own
// pointer type (may_alias); GCC and Clang lower them to what the target has.
typedef double D4 __attribute__((vector_size(32)));
typedef double D8 __attribute__((vector_size(64)));
template <class T, std::size_t N>
struct Unaligned {
  typedef T type __attribute__((vector_size(N * sizeof(T)), aligned(sizeof(T)), may_alias));
};

/// `to` = the sizeof(D) / 8 values from `at` (float or double), widened to double.
template <class D, class T>
inline void load(const T* at, D& to) {
  constexpr std::size_t n = sizeof(D) / sizeof(double);
  // GCC 12 lowers the generic float conversion in halves (two loads, an insert)
#if defined(__AVX512F__)
  if constexpr (std::is_same_v<T, float> && n == 8) {
    to = _mm512_maskz_cvtps_pd(0xFF, _mm256_loadu_ps(at));  // (maskz: GCC 12 warns on _mm512_cvtps_pd)
    return;
  }
#endif
#if defined(__AVX__)
  if constexpr (std::is_same_v<T, float> && n == 4) {
    to = _mm256_cvtps_pd(_mm_loadu_ps(at));
    return;
  }
#endif
  to = __builtin_convertvector(*reinterpret_cast<const typename Unaligned<T, n>::type*>(at), D);
}

// (a[0] + a[1]) + ... in dot8's fixed order: the result does not depend on the target's width.
inline double sum8(const D8& a) { return ((a[0] + a[1]) + (a[2] + a[3])) + ((a[4] + a[5]) + (a[6] + a[7])); }

}  // namespace panel_lanes

/// L y = w on the panel's pivots, then w[nc..nr) -= L(below) y: w holds nr values, the first nc
/// replaced by y. O(panel).
template <class T>
inline void panel_forward(const T* panel, std::size_t nc, std::size_t nr, double* __restrict w) {
  std::size_t j = 0;
  for (; j + 4 <= nc; j += 4) {
    const T* c[4] = {panel + j * nr, panel + (j + 1) * nr, panel + (j + 2) * nr, panel + (j + 3) * nr};
    for (std::size_t a = 0; a < 4; ++a) {  // the four pivots' triangle, a column at a time
      const double wa = w[j + a] / static_cast<double>(c[a][j + a]);
      w[j + a] = wa;
      for (std::size_t i = j + a + 1; i < j + 4; ++i) w[i] -= static_cast<double>(c[a][i]) * wa;
    }
    const double w0 = w[j], w1 = w[j + 1], w2 = w[j + 2], w3 = w[j + 3];
    // the same operations per entry, in the same order, as four column passes
    for (std::size_t i = j + 4; i < nr; ++i)
      w[i] = (((w[i] - static_cast<double>(c[0][i]) * w0) - static_cast<double>(c[1][i]) * w1) - static_cast<double>(c[2][i]) * w2) -
             static_cast<double>(c[3][i]) * w3;
  }
  for (; j < nc; ++j) {
    const T* col = panel + j * nr;
    const double wj = w[j] / static_cast<double>(col[j]);
    w[j] = wj;
    for (std::size_t i = j + 1; i < nr; ++i) w[i] -= static_cast<double>(col[i]) * wj;
  }
}

/// Lᵀ y = w[0..nc) - L(below)ᵀ w[nc..nr): the first nc values of w replaced by y. O(panel).
template <class T>
inline void panel_backward(const T* panel, std::size_t nc, std::size_t nr, double* __restrict w) {
  using panel_lanes::D8;
  std::size_t j = nc;
  for (; j % 4 != 0;) {  // the last columns past a multiple of four, one at a time
    --j;
    const T* col = panel + j * nr;
    w[j] = (w[j] - physics::detail::dot8(col + j + 1, w + j + 1, nr - j - 1)) / static_cast<double>(col[j]);
  }
  while (j > 0) {
    j -= 4;
    const T* c[4] = {panel + j * nr, panel + (j + 1) * nr, panel + (j + 2) * nr, panel + (j + 3) * nr};
    // rows j + 4 on (final already) for the four columns at once: eight partial sums each
    D8 part[4] = {};
    std::size_t i = j + 4;
    for (; i + 8 <= nr; i += 8) {
      D8 wi, l;
      __builtin_memcpy(&wi, w + i, sizeof wi);
      for (std::size_t a = 0; a < 4; ++a) {
        panel_lanes::load(c[a] + i, l);
        part[a] += l * wi;
      }
    }
    double dot[4];
    for (std::size_t a = 0; a < 4; ++a) {
      dot[a] = panel_lanes::sum8(part[a]);
      for (std::size_t k = i; k < nr; ++k) dot[a] += static_cast<double>(c[a][k]) * w[k];
    }
    for (std::size_t a = 4; a-- > 0;) {  // then the four pivots' triangle, bottom up
      double s = w[j + a] - dot[a];
      for (std::size_t k = j + a + 1; k < j + 4; ++k) s -= static_cast<double>(c[a][k]) * w[k];
      w[j + a] = s / static_cast<double>(c[a][j + a]);
    }
  }
}

}  // namespace sewn::physics::solve::detail
