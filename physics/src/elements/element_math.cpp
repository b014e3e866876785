#include "sewn/physics/elements/element_math.hpp"

#include <cmath>

#include <Eigen/Eigenvalues>

namespace sewn::physics::elements {

double project_psd(Eigen::Ref<Eigen::MatrixXd> H) {
  const Eigen::Index n = H.rows();
  // Gershgorin: every row with a_ii ≥ Σ|a_ij| proves H PSD without a decomposition.
  bool dominant = true;
  for (Eigen::Index i = 0; i < n && dominant; ++i) {
    double off = 0.0;
    for (Eigen::Index j = 0; j < n; ++j)
      if (j != i) off += std::abs(H(i, j));
    dominant = H(i, i) >= off;
  }
  if (dominant) return 0.0;
  const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eig(H);
  Eigen::VectorXd d = eig.eigenvalues();
  const double lowest = d.minCoeff();
  if (lowest >= 0.0) return 0.0;
  d = d.cwiseMax(0.0);
  H = eig.eigenvectors() * d.asDiagonal() * eig.eigenvectors().transpose();
  return lowest;
}

}  // namespace sewn::physics::elements
