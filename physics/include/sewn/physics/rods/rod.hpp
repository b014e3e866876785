#pragma once
// Rod: one discrete elastic rod (open or closed) on its own vertices — rest state, per-edge
// reference frames and material angles θ, per-vertex natural curvature and twist — with its
// energy, gradient and Hessian over all its degrees of freedom, the quasi-static twist solve
// and the time-parallel frame update. The Rods force term (rods_term.hpp) and the static
// solver (static_solve.hpp) are built on it; see stencils.hpp for the conventions.
//
// DOF order of the whole rod: q = (x_0, ..., x_{n−1}, θ^0, ..., θ^{m−1}), 3n + m entries, with
// m = n − 1 edges for an open rod and m = n for a closed one (edge j joins vertex j to j+1 mod n).

#include <span>
#include <stdexcept>
#include <utility>
#include <vector>

#include <Eigen/Core>
#include <Eigen/SparseCore>

#include "sewn/physics/rods/stencils.hpp"

namespace sewn::physics::rods {

using Points = Eigen::Matrix3Xd;

class Rod {
 public:
  /// Builds a rod whose rest shape, and current shape, is `rest` (3×n). Reference frames start
  /// space-parallel from `rest_directors[0]` (or any vector ⟂ the first edge), and the
  /// material frames at rest are `rest_directors` (one per edge, projected ⟂ the edge; empty:
  /// the reference frames, θ = 0). Natural curvatures and twist are read off that rest state.
  /// Throws InputError naming the vertex or edge: fewer than 2 vertices (3 if closed), a
  /// non-finite or zero-length edge, a rest kink of 180° or more, a director parallel to its
  /// edge, a wrong number of directors. O(n).
  Rod(const Points& rest, bool closed, const Section& section, std::span<const Vec3> rest_directors = {});

  [[nodiscard]] int num_vertices() const { return static_cast<int>(rest_length_.size()) + (closed_ ? 0 : 1); }
  [[nodiscard]] int num_edges() const { return static_cast<int>(rest_length_.size()); }
  [[nodiscard]] int num_dofs() const { return 3 * num_vertices() + num_edges(); }
  [[nodiscard]] bool closed() const { return closed_; }
  [[nodiscard]] const Section& section() const { return section_; }
  /// Vertices (i−1, i, i+1) and edges (i−1, i) of bend–twist stencil s (open: s = 0..n−3 for
  /// vertex s+1; closed: s = 0..n−1 for vertex s).
  [[nodiscard]] int num_stencils() const { return static_cast<int>(stencils_.size()); }
  [[nodiscard]] std::array<int, 3> stencil_vertices(int s) const;
  [[nodiscard]] std::array<int, 2> stencil_edges(int s) const;
  [[nodiscard]] double rest_length(int edge) const { return rest_length_[static_cast<std::size_t>(edge)]; }
  [[nodiscard]] const BendTwistRest& stencil_rest(int s) const { return stencils_[static_cast<std::size_t>(s)].rest; }
  [[nodiscard]] const BendTwistFrames& stencil_frames(int s) const { return stencils_[static_cast<std::size_t>(s)].frames; }

  /// Replaces the natural curvatures and twist of stencil s (e.g. a straight rest state for a
  /// rod built closed). Throws InputError if s is out of range or a value is not finite. O(1).
  void set_natural_strains(int s, double kappa1, double kappa2, double twist);

  // ---- material angles (the rod's own state)
  [[nodiscard]] std::span<const double> theta() const { return theta_; }
  /// Sets θ of an edge (a clamp's prescribed value, or a restart). Throws InputError if out of range.
  void set_theta(int edge, double value);
  /// Holds θ of an edge at its value in twist solves (a clamped end). O(1).
  void fix_theta(int edge, bool fixed = true);
  [[nodiscard]] bool theta_fixed(int edge) const { return theta_fixed_[static_cast<std::size_t>(edge)] != 0; }

  /// Total elastic energy at positions x (3×n) and the stored θ. O(n).
  [[nodiscard]] double energy(const Points& x) const;
  /// Energy and gradient over all DOFs (rod DOF order); with `hessian`, also the Hessian as
  /// triplets (rows/cols in rod DOF order, duplicates to be summed). O(n); the Hessian costs
  /// one AD pass per stencil (~2.4 µs each).
  double evaluate(const Points& x, Eigen::VectorXd& gradient, std::vector<Eigen::Triplet<double>>* hessian) const;

  /// Minimises the energy over the free θ with x held (Newton on the tridiagonal θ block —
  /// cyclic for a closed rod — with a backtracking line search), from the stored θ. Returns
  /// the Newton iterations used. Afterwards ∂E/∂θ = 0 on free edges, so the position
  /// gradient of evaluate() is the exact gradient of the reduced energy min_θ E (envelope
  /// theorem). A rod that turns_freely() with no angle held has a singular θ block along
  /// (1, ..., 1): the solve keeps to the directions orthogonal to it, so the angles' mean stays
  /// where it was (no hold needed). Throws SolveError if it does not converge in 100
  /// iterations. `held` (empty, or one flag per edge) holds more angles at their value, beside
  /// the fixed ones (angles some other term turns: a connection's). O(n) per iteration.
  int solve_twist(const Points& x, std::span<const unsigned char> held = {});
  /// Whether the energy is unchanged when every θ turns by the same angle: a round section
  /// (EI1 = EI2) and no natural curvature (|κ̄| ≤ 1e-12) at every stencil. O(n).
  [[nodiscard]] bool turns_freely() const;

  /// The time-parallel update after an accepted step (or a static Newton iteration): each
  /// edge's reference director is transported from its stored tangent to the current one, and
  /// the tracked reference twist of each vertex takes its current, unwrapped value. θ and the
  /// energy at x are unchanged. O(n).
  void update_frames(const Points& x);
  /// Current reference director a1 and material directors (m1, m2) of an edge at x. O(1).
  [[nodiscard]] Vec3 reference_director(const Points& x, int edge) const;
  [[nodiscard]] std::pair<Vec3, Vec3> material_directors(const Points& x, int edge) const;
  /// Tracked reference twist of stencil s at x (unwrapped against the last update). O(1).
  [[nodiscard]] double reference_twist(const Points& x, int s) const;

  /// What the rod carries from one accepted step to the next beside the positions: θ, the
  /// reference frames (t̄, ā1 per edge) and the tracked reference twist of each stencil at the
  /// last frame update. Everything else follows from the rest shape. A rod built from the same
  /// rest shape and given this back continues bit for bit (checkpoints).
  struct State {
    std::vector<double> theta;          ///< per edge
    std::vector<Vec3> tangent, director;  ///< per edge
    std::vector<double> reference_twist;  ///< per stencil
  };
  [[nodiscard]] State state() const;
  /// Takes up a state from state(). Throws InputError (the rod unchanged) if a size does not
  /// match this rod or a value is not finite. O(n).
  void restore(const State& s);

 private:
  struct Stencil {
    BendTwistRest rest;
    BendTwistFrames frames;
  };
  [[nodiscard]] BendTwistEval eval_stencil(const Points& x, int s, Want want) const;
  void refresh_stencil_frames(int s);

  bool closed_;
  Section section_;
  std::vector<double> rest_length_;
  std::vector<Vec3> tangent_, director_;  // per edge: t̄ and ā1 at the last frame update
  std::vector<double> theta_;
  std::vector<unsigned char> theta_fixed_;
  std::vector<Stencil> stencils_;
};

/// A twist or static solve that did not converge (the rod's θ is left at its last iterate).
class SolveError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

}  // namespace sewn::physics::rods
