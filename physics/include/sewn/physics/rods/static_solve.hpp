#pragma once
// Static equilibrium of one rod: minimises its elastic energy minus the work of dead loads
// and end moments over the free positions and material angles — the solver behind the
// analytic validation cases (pure twist, ring, elastica, buckling) and any quasi-static use.

#include <vector>

#include "sewn/physics/rods/rod.hpp"
#include "sewn/physics/types.hpp"

namespace sewn::physics::rods {

/// A conservative moment M (N·m) about a fixed unit axis acting on one edge: potential −M ψ,
/// ψ = the edge's angle in the plane ⟂ axis, tracked continuously (it may exceed π).
struct EdgeMoment {
  int edge = 0;
  Vec3 axis{0, 0, 1};
  double moment = 0;
};

struct StaticProblem {
  std::vector<AxisMask> fixed;  ///< per vertex (empty: all free); clamp an end by fixing two vertices and θ
  Points forces;                ///< dead loads per vertex, N (0 columns: none)
  std::vector<EdgeMoment> moments;
  double tolerance = 1e-12;     ///< on the Newton step, relative to the mean rest edge length (θ: rad)
  int max_iterations = 500;
};

struct StaticResult {
  int iterations = 0;
  double energy = 0;     ///< elastic energy at the solution
  double potential = 0;  ///< energy − work of the loads
};

/// Newton with a positive-definite shift (so every step descends), steps limited to half an
/// edge and π/4 per angle, Armijo backtracking; the rod's frames are updated after every
/// accepted iteration (so large rotations stay far from the transport singularity). x (3×n) is
/// the start and receives the solution; the rod's θ is updated. Throws InputError for loads or
/// masks of the wrong size or non-finite, SolveError if it does not converge. O(n) per iteration.
StaticResult solve_static(Rod& rod, Points& x, const StaticProblem& problem);

/// Number of negative eigenvalues of the Hessian of the potential over the free DOFs at x (by
/// Sylvester's law of inertia, from an LDLᵀ factorisation): 0 at a stable equilibrium. Used to
/// bracket buckling loads. O(n).
[[nodiscard]] int unstable_modes(const Rod& rod, const Points& x, const StaticProblem& problem);

}  // namespace sewn::physics::rods
