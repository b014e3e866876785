// The fine level of sa-pcg on padded vectors (fine_level.hpp).

#include "fine_level.hpp"

namespace sewn::physics::solve::detail {

void FineLevel::bind(const BlockMatrix& A, std::span<const double> free_dof) {
  A_ = &A;
  nodes_ = static_cast<std::size_t>(A.size());
  packed_ = pack_symmetric_blocks(A, packed_ws_);
  free4_.resize(4 * nodes_);
  pad(free_dof, free4_.data());
  inverse_.resize(9 * nodes_);
  block_jacobi_inverse(A, free_dof, inverse_);
}

double FineLevel::product(const double* p, double* y) {
  if (packed_) return packed_symmetric_product(packed_ws_, p, y, free4_.data(), static_cast<Index>(nodes_));
  x3_.resize(3 * nodes_);
  y3_.resize(3 * nodes_);
  unpad(p, x3_);
  A_->multiply(x3_, y3_);
  double py = 0;
  for (std::size_t i = 0; i < nodes_; ++i) {
    for (std::size_t a = 0; a < 3; ++a) {
      const std::size_t o = 4 * i + a;
      y[o] = free4_[o] * y3_[3 * i + a];
      py += p[o] * y[o];
    }
    y[4 * i + 3] = 0.0;
  }
  return py;
}

void FineLevel::smooth_step(const double* v, double* d, double scale, double keep) const {
  for (std::size_t i = 0; i < nodes_; ++i) {
    const double* D = inverse_.data() + 9 * i;  // column-major
    const double* x = v + 4 * i;
    double* o = d + 4 * i;
    const double* f = free4_.data() + 4 * i;
    for (int a = 0; a < 3; ++a)
      o[a] = f[a] * (keep * o[a] + scale * (D[a] * x[0] + D[3 + a] * x[1] + D[6 + a] * x[2]));
    o[3] = 0.0;
  }
}

void FineLevel::pad(std::span<const double> v3, double* v4) {
  for (std::size_t i = 0; i < v3.size() / 3; ++i) {
    for (std::size_t a = 0; a < 3; ++a) v4[4 * i + a] = v3[3 * i + a];
    v4[4 * i + 3] = 0.0;
  }
}

void FineLevel::unpad(const double* v4, std::span<double> v3) {
  for (std::size_t i = 0; i < v3.size() / 3; ++i)
    for (std::size_t a = 0; a < 3; ++a) v3[3 * i + a] = v4[4 * i + a];
}

}  // namespace sewn::physics::solve::detail
