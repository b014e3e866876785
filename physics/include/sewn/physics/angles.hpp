#pragma once
// AngleTable: scalar degrees of freedom beyond node positions — a rod's twist angle per edge
// when the rods integrate it (rods::Rods::use_angle_dofs) — with rate, inertia and a fixed
// flag. A System holds one; it is empty unless a term asks for angles, and then integrators
// that do not integrate angles refuse the system. The Newton integrator appends the angles to
// its flat DOF arrays after the 3n positions.
//
// In the Jacobian, angles sit in extra 3×3 block rows after the node rows, three angles per
// block (AngleLayout), so the block solvers need no second matrix type; a block's unused
// components are fixed.

#include <span>
#include <string>
#include <vector>

#include "sewn/physics/types.hpp"

namespace sewn::physics {

/// Where angle a sits in the block matrix: block row first_block + a/3, component a % 3.
struct AngleLayout {
  Index first_block = 0;  ///< the number of nodes
  [[nodiscard]] Index block(Index a) const { return first_block + a / 3; }
  [[nodiscard]] int component(Index a) const { return static_cast<int>(a % 3); }
  /// Block rows the angles need: ⌈count/3⌉.
  [[nodiscard]] static Index blocks_for(Index count) { return (count + 2) / 3; }
};

class AngleTable {
 public:
  /// Appends `count` angles with the given values (rad), zero rates, inertia (kg·m², ≥ 0; 0: no
  /// inertia, the angle is solved with the positions in every Newton step) and fixed flags
  /// (a fixed angle follows its rate) and lengths (m, > 0; empty: 1 m each): the displacement
  /// per radian of what the angle turns, e.g. a rod section's radius of gyration, by which
  /// the Newton integrator's stopping test counts an angle update as a distance, in the units
  /// of the position updates beside it. `owner` names them in errors. Returns the first index.
  /// Throws InputError on a non-finite value, a negative or non-finite inertia, a length not
  /// finite and > 0, or sizes that differ. O(count).
  Index add(const std::string& owner, std::span<const double> values, std::span<const double> inertias,
            std::span<const unsigned char> fixed, std::span<const double> lengths = {});
  [[nodiscard]] Index size() const { return static_cast<Index>(value_.size()); }
  [[nodiscard]] bool empty() const { return value_.empty(); }
  [[nodiscard]] std::span<double> values() { return value_; }
  [[nodiscard]] std::span<const double> values() const { return value_; }
  [[nodiscard]] std::span<double> rates() { return rate_; }
  [[nodiscard]] std::span<const double> rates() const { return rate_; }
  [[nodiscard]] std::span<const double> inertias() const { return inertia_; }
  [[nodiscard]] std::span<const double> lengths() const { return length_; }
  [[nodiscard]] bool fixed(Index a) const { return fixed_[a] != 0; }
  /// Fixes or frees angle a (a fixed angle moves at its rate). Throws InputError if out of range.
  void set_fixed(Index a, bool on);
  /// Sets angle a's length (see add) after the fact, for a term that knows it only once its
  /// angles exist: a Morley edge's mid-normal takes the height of its triangles over the edge
  /// (taken as 1 m, a mid-normal that moved a 5 mm cell by 1e-7 m kept Newton iterating long
  /// after the positions had converged). Throws InputError if a is out of range or metres is
  /// not finite and > 0.
  void set_length(Index a, double metres);
  /// Marks angle a as condensed: its term solves it inside every evaluation (a rod's
  /// quasi-static twist, Rods::condense_twist) and reads it from its own state, not from the
  /// table. The Newton integrator keeps a condensed angle in its linear system only, so the
  /// position part of each step is the Newton step of the reduced energy min_θ E (the solve
  /// does the Schur complement H_xx − H_xθ H_θθ⁻¹ H_θx without forming it), and never moves it
  /// (its value here stays as added). Condensing zeroes its inertia (it is quasi-static).
  /// Throws InputError if a is out of range.
  void set_condensed(Index a, bool on);
  [[nodiscard]] bool condensed(Index a) const { return condensed_[a] != 0; }
  /// Changes whenever angles are added (the Jacobian pattern grows).
  [[nodiscard]] std::uint64_t topology_version() const { return topology_version_; }

 private:
  std::vector<double> value_, rate_, inertia_, length_;
  std::vector<unsigned char> fixed_, condensed_;
  std::uint64_t topology_version_ = 0;
};

}  // namespace sewn::physics
