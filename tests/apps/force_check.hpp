#pragma once
// The check the cut tests make after every edit: the forces are still the energy's gradient.

#include <algorithm>
#include <cmath>

#include <Eigen/Core>

#include "sewn/physics/mss_model.hpp"

namespace sewn::app::test {

/// Largest difference between the force on particle n and −∂E/∂x_n by central differences
/// (h = 1e-7 per axis), against the force's size: |f_a + ∂E/∂x_a| / (1 + |f|). Leaves the
/// positions as they were. Two energy evaluations per axis.
inline double force_error(physics::MssModel<3>& model, physics::Index n) {
  physics::System& sys = model.system();
  sys.compute_forces();
  const Eigen::Vector3d f = model.nodes().force(n), x = model.nodes().position(n);
  double worst = 0;
  for (int a = 0; a < 3; ++a) {
    const double h = 1e-7;
    Eigen::Vector3d xp = x, xm = x;
    xp[a] += h;
    xm[a] -= h;
    model.nodes().set_position(n, xp);
    const double ep = sys.potential_energy();
    model.nodes().set_position(n, xm);
    const double em = sys.potential_energy();
    model.nodes().set_position(n, x);
    worst = std::max(worst, std::abs(-(ep - em) / (2 * h) - f[a]) / (1 + f.norm()));
  }
  return worst;
}

}  // namespace sewn::app::test
