#pragma once
// NodeTable: the dense state of every node (particle) of a scene. Positions, velocities and
// forces are 3n arrays, node-major ([x0 y0 z0 x1 y1 z1 ...]), so each maps both as a 3×n
// Eigen matrix (column = node) and as one 3n vector for the solvers. Masses and fixed-axis
// flags are n arrays; the inverse mass per degree of freedom (0 on fixed axes) is kept up to
// date so that explicit updates are one branch-free loop. Hot loops read only these arrays,
// never the combinatorial map.
//
// Removal leaves a tombstone (mass 0, every axis fixed, zero velocity: the node is inert and
// invisible to energies); System::compact_nodes() renumbers and returns the old->new map.

#include <cstdint>
#include <span>
#include <vector>

#include <Eigen/Core>

#include "sewn/physics/aligned.hpp"
#include "sewn/physics/types.hpp"

namespace sewn::physics {

class System;

class NodeTable {
 public:
  using Vec3 = Eigen::Vector3d;
  using Map3X = Eigen::Map<Eigen::Matrix3Xd>;
  using ConstMap3X = Eigen::Map<const Eigen::Matrix3Xd>;
  using MapX = Eigen::Map<Eigen::VectorXd>;
  using ConstMapX = Eigen::Map<const Eigen::VectorXd>;

  /// Appends a free node; returns its index. Throws InputError on a non-finite position or
  /// velocity, or a mass that is not finite and > 0. Amortised O(1); invalidates spans and
  /// maps into the arrays (not indices).
  Index add(const Vec3& x, const Vec3& v, double mass);
  /// Appends a copy of node i (position, velocity, mass, fixed axes; zero force) and returns
  /// its index: the duplication step of a cut. Same cost and invalidation as add().
  Index duplicate(Index i);
  /// Reserves storage for n nodes. Invalidates spans and maps if it reallocates.
  void reserve(Index n);
  /// Number of node slots, removed ones included (arrays have 3·size() entries). O(1).
  [[nodiscard]] Index size() const { return static_cast<Index>(mass_.size()); }
  /// Number of nodes not removed. O(1).
  [[nodiscard]] Index num_alive() const { return alive_count_; }

  /// Makes node i inert (mass 0, all axes fixed, zero velocity and force) until the next
  /// System::compact_nodes(), which drops it. Elements of force terms must stop referring to
  /// it before that. Throws InputError if i is out of range or already removed. O(1).
  void remove(Index i);
  [[nodiscard]] bool is_alive(Index i) const { return i < size() && alive_[i] != 0; }

  // ---- whole arrays (3n node-major, or n); invalidated by add/duplicate/reserve/compact. Write
  // access to positions or velocities clears state_known_finite().
  [[nodiscard]] std::span<double> x() {
    state_finite_ = false;
    return std::span<double>{x_.data(), x_.size()};
  }
  [[nodiscard]] std::span<const double> x() const { return {x_.data(), x_.size()}; }
  [[nodiscard]] std::span<double> v() {
    state_finite_ = false;
    return std::span<double>{v_.data(), v_.size()};
  }
  [[nodiscard]] std::span<const double> v() const { return {v_.data(), v_.size()}; }
  [[nodiscard]] std::span<double> f() { return {f_.data(), f_.size()}; }
  [[nodiscard]] std::span<const double> f() const { return {f_.data(), f_.size()}; }
  [[nodiscard]] std::span<const double> masses() const { return {mass_.data(), mass_.size()}; }
  /// 1/m on free axes, 0 on fixed axes and removed nodes (3n).
  [[nodiscard]] std::span<const double> inverse_mass_dof() const { return {inv_mass_.data(), inv_mass_.size()}; }
  /// Fixed-axis mask of every node (n).
  [[nodiscard]] std::span<const AxisMask> fixed_masks() const { return {fixed_.data(), fixed_.size()}; }
  /// The same arrays as Eigen maps: 3×n (column = node) or a 3n vector.
  [[nodiscard]] Map3X positions() {
    state_finite_ = false;
    return Map3X{x_.data(), 3, size()};
  }
  [[nodiscard]] ConstMap3X positions() const { return {x_.data(), 3, size()}; }
  [[nodiscard]] Map3X velocities() {
    state_finite_ = false;
    return Map3X{v_.data(), 3, size()};
  }
  [[nodiscard]] ConstMap3X velocities() const { return {v_.data(), 3, size()}; }
  [[nodiscard]] Map3X forces() { return {f_.data(), 3, size()}; }
  [[nodiscard]] ConstMap3X forces() const { return {f_.data(), 3, size()}; }
  [[nodiscard]] MapX positions_flat() {
    state_finite_ = false;
    return MapX{x_.data(), 3 * Eigen::Index{size()}};
  }
  [[nodiscard]] MapX velocities_flat() {
    state_finite_ = false;
    return MapX{v_.data(), 3 * Eigen::Index{size()}};
  }
  [[nodiscard]] MapX forces_flat() { return {f_.data(), 3 * Eigen::Index{size()}}; }
  /// The current state as force terms read it.
  [[nodiscard]] StateView state() const { return {x(), v(), masses()}; }

  // ---- one node; each throws InputError if i is out of range or removed. O(1).
  [[nodiscard]] Vec3 position(Index i) const;
  [[nodiscard]] Vec3 velocity(Index i) const;
  [[nodiscard]] Vec3 force(Index i) const;
  [[nodiscard]] double mass(Index i) const;
  [[nodiscard]] AxisMask fixed(Index i) const;
  /// Sets a position (must be finite). Invalidates nothing.
  void set_position(Index i, const Vec3& x);
  /// Sets a velocity (must be finite). On fixed axes this prescribes the motion: integrators
  /// keep fixed-axis velocities constant, so a fixed axis with a velocity is kinematic.
  void set_velocity(Index i, const Vec3& v);
  /// Sets the mass (finite, > 0), e.g. after a cut splits a particle. Bumps parameter_version().
  void set_mass(Index i, double m);
  /// Fixes the given axes and zeroes the velocity on them (set_velocity afterwards to
  /// prescribe a motion). Bumps parameter_version().
  void fix(Index i, AxisMask axes = all_axes);
  /// Frees the given axes. Bumps parameter_version().
  void unfix(Index i, AxisMask axes = all_axes);
  /// Number of live nodes with at least one fixed axis. O(1).
  [[nodiscard]] Index num_fixed_nodes() const { return fixed_count_; }

  /// True if every position and velocity is known to be finite: an integrator found the results
  /// of its own update finite, and nothing has had write access to them since (every non-const
  /// x(), v(), positions(), velocities() and *_flat() clears it; the checked setters keep it).
  /// Lets the next step check only the forces. A value written later through a span or map
  /// obtained earlier is not seen here: it reaches the forces (and their check) if any term
  /// reads that node, and otherwise the next step's check of its own update. O(1).
  [[nodiscard]] bool state_known_finite() const { return state_finite_; }
  /// Records that every position and velocity was just found finite (integrators call it after
  /// checking their update). O(1).
  void mark_state_finite() { state_finite_ = true; }

  /// Changes whenever nodes are added, removed or renumbered (matrix size and pattern).
  /// Versions increase and are drawn from one counter for the whole process: no two tables
  /// reach the same version by changes of their own, so a cache keyed by a table's versions is
  /// not fooled by another table assigned in its place (a copy shares its versions with its
  /// content). 0 for a new, empty table.
  [[nodiscard]] std::uint64_t topology_version() const { return topology_version_; }
  /// Changes whenever a mass or a fixed flag changes (stable step, preconditioner); drawn from
  /// the same counter as topology_version().
  [[nodiscard]] std::uint64_t parameter_version() const { return parameter_version_; }

 private:
  friend class System;
  // Drops removed nodes, keeping order; returns old index -> new index (invalid_index for
  // removed). Only System calls it, so force terms are renumbered at the same time. O(n).
  std::vector<Index> compact();
  void check_node(Index i, const char* where) const;
  void refresh_inverse_mass(Index i);

  AlignedVector<double> x_, v_, f_, inv_mass_;
  AlignedVector<double> mass_;
  std::vector<AxisMask> fixed_;
  std::vector<std::uint8_t> alive_;
  bool state_finite_ = false;
  Index alive_count_ = 0;
  Index fixed_count_ = 0;
  std::uint64_t topology_version_ = 0;
  std::uint64_t parameter_version_ = 0;
};

}  // namespace sewn::physics
