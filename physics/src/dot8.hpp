// The dot product every CG loop of the physics module uses (cg.cpp, solve/kept_pcg.cpp) and the
// single-precision factor's triangular solves (solve/float_factor.cpp).
#pragma once

#include <cstddef>

namespace sewn::physics::detail {

// Σ x[i] · y[i] over n entries, x widened to double when it is float. Eight independent partial
// sums: a single running sum is bound by the add latency, and the compiler may not reorder it
// itself (no -ffast-math); their fixed order keeps the result independent of the build's
// vectorisation (deterministic).
template <class T>
inline double dot8(const T* __restrict x, const double* __restrict y, std::size_t n) {
  double part[8] = {};
  const std::size_t n8 = n - n % 8;
  for (std::size_t k = 0; k < n8; k += 8)
    for (std::size_t q = 0; q < 8; ++q) part[q] += static_cast<double>(x[k + q]) * y[k + q];
  double s = ((part[0] + part[1]) + (part[2] + part[3])) + ((part[4] + part[5]) + (part[6] + part[7]));
  for (std::size_t k = n8; k < n; ++k) s += static_cast<double>(x[k]) * y[k];
  return s;
}

}  // namespace sewn::physics::detail
