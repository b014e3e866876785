#pragma once
// What the cut tests check after every edit: the forces are still the energy's gradient, and
// which hinges kept or lost their energy.

#include <algorithm>
#include <cmath>
#include <vector>

#include <Eigen/Core>

#include "sewn/apps/continuum.hpp"
#include "sewn/physics/mss_model.hpp"
#include "sewn/physics/shells/shell_terms.hpp"

namespace sewn::app::test {

/// −∂E/∂x_a at particle n by central differences with step h, the positions left as they were.
/// Two energy evaluations.
inline double energy_slope(physics::MssModel<3>& model, physics::Index n, int a, double h) {
  physics::System& sys = model.system();
  const Eigen::Vector3d x = model.nodes().position(n);
  Eigen::Vector3d xp = x, xm = x;
  xp[a] += h;
  xm[a] -= h;
  model.nodes().set_position(n, xp);
  const double ep = sys.potential_energy();
  model.nodes().set_position(n, xm);
  const double em = sys.potential_energy();
  model.nodes().set_position(n, x);
  return -(ep - em) / (2 * h);
}

/// Largest difference between the force on particle n and −∂E/∂x_n by central differences
/// (h = 1e-7 per axis), against the force's size: |f_a + ∂E/∂x_a| / (1 + |f|).
inline double force_error(physics::MssModel<3>& model, physics::Index n) {
  model.system().compute_forces();
  const Eigen::Vector3d f = model.nodes().force(n);
  double worst = 0;
  for (int a = 0; a < 3; ++a) worst = std::max(worst, std::abs(energy_slope(model, n, a, 1e-7) - f[a]) / (1 + f.norm()));
  return worst;
}

/// Each hinge's energy at the model's state (0 for retired ones).
inline std::vector<double> hinge_energies(const ContinuumParts& parts, const physics::MssModel<3>& model) {
  const auto s = model.system().state();
  std::vector<double> e(parts.hinges->size(), 0.0);
  for (physics::Index h = 0; h < e.size(); ++h)
    if (parts.hinges->is_alive(h)) e[h] = parts.hinges->element_energy(h, parts.hinges->gather(s, h));
  return e;
}

}  // namespace sewn::app::test
