#pragma once
// The bare loop: the same semi-implicit step as the library's (the seed's per-spring
// viscosity, gravity, fixed points, the library's degenerate-spring guard), written as the
// fastest plain-array code we could find for this machine, so that library / bare is the
// measured cost of living on the map and of the library's generality. No map, no force-term
// interface, no health checks.
//
// Layout, chosen by measurement (bench/mss/notes.md, "The bare loop"): positions, velocities
// and the force accumulator hold 4 doubles per node (x, y, z, 0), so every node is one aligned
// 256-bit load that never splits a cache line; springs are a structure of arrays in mesh-edge
// order. Gravity enters as an acceleration g on free axes, and the update zeroes the
// accumulator as it reads it, so a step is two passes: springs, then nodes.

#include <array>
#include <cstdint>
#include <vector>

#include "model.hpp"
#include "sewn/physics/aligned.hpp"

namespace sewn::bench::mss {

class Bare {
 public:
  /// Throws std::runtime_error if spec has drag (the cost cases have none; not implemented).
  explicit Bare(const ModelSpec& spec);

  /// One semi-implicit step: v += h (F/m), x += h v, F = springs + gravity; fixed axes stay.
  void step(double h);

  [[nodiscard]] Counts counts() const { return {n_, k_.size()}; }
  void set_state(const State& s);
  [[nodiscard]] State state() const;
  void save();
  void restore();
  /// Forces at the current state, per mesh point (springs + gravity; fixed points included).
  [[nodiscard]] std::vector<double> forces();
  [[nodiscard]] double max_abs_position() const;

 private:
  void accumulate_springs();

  template <class T>
  using Vec = physics::AlignedVector<T>;
  std::size_t n_ = 0;
  Vec<double> x_, v_, acc_;    // 4 per node
  Vec<double> inv_mass_, g_;   // 4 per node: 1/m and g on free axes, 0 on fixed axes and lane 3
  Vec<double> mass_;           // per node, for forces()
  std::array<double, 3> gravity_{};
  Vec<std::uint32_t> i_, j_;
  Vec<double> k_, l_, gamma_;
  Vec<double> saved_x_, saved_v_;
};

}  // namespace sewn::bench::mss
