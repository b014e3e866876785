// Internal: the triangular solves on one dense supernodal panel, whatever precision it is stored
// in (the arithmetic is double): BlockCholesky's solves and the float copy of CHOLMOD's factor.
//
// A panel holds nc columns of L as nr rows, column-major (leading dimension nr), the first nc
// rows its own pivots (lower triangle; the upper one is not read), the others the rows below.
#pragma once

#include <cstddef>

#include "../dot8.hpp"

namespace sewn::physics::solve::detail {

/// L y = w on the panel's pivots, then w[nc..nr) -= L(below) y: w holds nr values, the first nc
/// replaced by y. O(panel).
template <class T>
inline void panel_forward(const T* panel, std::size_t nc, std::size_t nr, double* __restrict w) {
  for (std::size_t j = 0; j < nc; ++j) {
    const T* col = panel + j * nr;
    const double wj = w[j] / static_cast<double>(col[j]);
    w[j] = wj;
    for (std::size_t i = j + 1; i < nr; ++i) w[i] -= static_cast<double>(col[i]) * wj;
  }
}

/// Lᵀ y = w[0..nc) - L(below)ᵀ w[nc..nr): the first nc values of w replaced by y. O(panel).
template <class T>
inline void panel_backward(const T* panel, std::size_t nc, std::size_t nr, double* __restrict w) {
  for (std::size_t j = nc; j-- > 0;) {
    const T* col = panel + j * nr;
    w[j] = (w[j] - physics::detail::dot8(col + j + 1, w + j + 1, nr - j - 1)) / static_cast<double>(col[j]);
  }
}

}  // namespace sewn::physics::solve::detail
