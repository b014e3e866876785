#pragma once
// Refinement criteria beside the 2014 paper's diagonal strain (criterion.hpp): the strain
// energy density, a user region, the distance to a point (a tool tip), contact with rigid
// obstacles, and a combination of several. Each is a Criterion<D> for adapt() and Adapter, with its own hysteresis for
// coarsening.

#include <functional>
#include <memory>
#include <vector>

#include <Eigen/Core>

#include "sewn/physics/obstacles/obstacles.hpp"
#include "sewn/refine/criterion.hpp"

namespace sewn::refine {

/// The mean of the current positions of element e's particles. O(particles of e).
template <int D>
[[nodiscard]] Eigen::Vector3d element_centroid(const MssModel<D>& m, Index e);

/// Refines the elements whose strain energy density is above a threshold (J/m³): the energy
/// ½k(l − l₀)² of the element's own springs, its sides (taken corner to corner, with the
/// stiffness the element gives each) and its diagonals, over its rest volume (area × thickness
/// in 2D). Zero under rigid motion; unlike the diagonal strain it weighs the material's
/// stiffness and sees the sides' stretch too. Allows coarsening below a quarter of the
/// threshold (half the strain, as the diagonal strain's hysteresis). O(sides of the element).
template <int D>
class StrainEnergy : public Criterion<D> {
 public:
  /// Throws physics::InputError unless the threshold is finite and > 0.
  explicit StrainEnergy(double threshold);
  [[nodiscard]] bool wants_refinement(const MssModel<D>& m, Index e) const override;
  [[nodiscard]] bool allows_coarsening(const MssModel<D>& m, Index e) const override;
  /// Element e's strain energy density, J/m³.
  [[nodiscard]] static double density(const MssModel<D>& m, Index e);

 private:
  double threshold_;
};

/// Refines the elements whose rest centroid (the mean of their particles' rest positions)
/// satisfies a predicate: a zone of interest fixed in the material; allows coarsening outside it.
/// O(particles of the element) per call.
template <int D>
class InRegion : public Criterion<D> {
 public:
  using Predicate = std::function<bool(const Eigen::Vector3d&)>;
  /// Throws physics::InputError for an empty predicate.
  explicit InRegion(Predicate inside);
  [[nodiscard]] bool wants_refinement(const MssModel<D>& m, Index e) const override;
  [[nodiscard]] bool allows_coarsening(const MssModel<D>& m, Index e) const override;

 private:
  Predicate inside_;
};

/// Refines the elements whose current centroid is within `radius` of a point (which a tool may
/// move between steps); allows coarsening beyond twice the radius (hysteresis).
template <int D>
class NearPoint : public Criterion<D> {
 public:
  /// Throws physics::InputError unless radius > 0 and the point is finite.
  NearPoint(const Eigen::Vector3d& point, double radius);
  void move_to(const Eigen::Vector3d& point);
  [[nodiscard]] bool wants_refinement(const MssModel<D>& m, Index e) const override;
  [[nodiscard]] bool allows_coarsening(const MssModel<D>& m, Index e) const override;

 private:
  Eigen::Vector3d point_;
  double radius_;
};

/// Refines the elements one of whose particles is inside a rigid obstacle (penetration depth
/// > 0: it is in contact); allows coarsening when none is. O(particles of e · shapes).
template <int D>
class InContact : public Criterion<D> {
 public:
  /// Throws physics::InputError for an empty list of shapes.
  explicit InContact(std::vector<physics::obstacles::Shape> shapes);
  [[nodiscard]] bool wants_refinement(const MssModel<D>& m, Index e) const override;
  [[nodiscard]] bool allows_coarsening(const MssModel<D>& m, Index e) const override;

 private:
  [[nodiscard]] bool touches(const MssModel<D>& m, Index e) const;
  std::vector<physics::obstacles::Shape> shapes_;
};

/// Several criteria at once: refine when any wants it, coarsen only when all allow it.
template <int D>
class AnyOf : public Criterion<D> {
 public:
  /// Throws physics::InputError for an empty list or a null criterion.
  explicit AnyOf(std::vector<std::unique_ptr<Criterion<D>>> criteria);
  [[nodiscard]] bool wants_refinement(const MssModel<D>& m, Index e) const override;
  [[nodiscard]] bool allows_coarsening(const MssModel<D>& m, Index e) const override;

 private:
  std::vector<std::unique_ptr<Criterion<D>>> criteria_;
};

}  // namespace sewn::refine
