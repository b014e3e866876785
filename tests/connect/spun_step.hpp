#pragma once
// One Newton step of a joint test's system with a rod angle spun fast, shared by the point and
// curve connection tests of the trial cap (max_trial_turn).

#include <cmath>
#include <vector>

#include "sewn/physics/integrate/newton_euler.hpp"
#include "sewn/physics/system.hpp"

namespace sewn::connect::test {

/// One step h = 0.01 s of `sys` (direct solve, to 1e-9 m/s, up to 200 iterations) with angle
/// `angle` turning at `turn` rad per step; returns the state after it (positions, then every
/// angle) and the step's report in `rep`. Throws NewtonError as the step does.
inline std::vector<double> spun_step(physics::System& sys, physics::Index angle, double turn, physics::integrate::NewtonReport& rep) {
  const double h = 0.01;
  sys.angles().rates()[angle] = turn / h;
  physics::integrate::NewtonEulerOptions o;
  o.solver = physics::integrate::LinearSolver::ldlt;
  o.velocity_tolerance = 1e-9;
  o.max_iterations = 200;
  physics::integrate::NewtonEuler newton(o);
  rep = newton.step(sys, h);
  std::vector<double> q(sys.nodes().x().begin(), sys.nodes().x().end());
  for (std::size_t a = 0; a < sys.angles().size(); ++a) q.push_back(sys.angles().values()[a]);
  return q;
}

}  // namespace sewn::connect::test
