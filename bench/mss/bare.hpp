#pragma once
// The bare loop: the same semi-implicit step as the library's (the seed's per-spring
// viscosity, gravity, fixed points, the library's degenerate-spring guard), written as the
// fastest plain-array code we could find for this machine, so that library / bare is the
// measured cost of living on the map and of the library's generality. No map, no force-term
// interface, no health checks.
//
// Layout, chosen by measurement (bench/mss/notes.md, "The bare loop"): every node quantity is
// one array per axis, and the springs are grouped into chunks of eight whose ends are
// consecutive nodes (spring q of a chunk joins i0 + q and j0 + q), so a chunk reads and writes
// contiguous lanes; springs in no such run are a short list done one at a time. Gravity enters
// as an acceleration g on free axes, and the update zeroes the accumulators as it reads them,
// so a step is two passes: springs, then nodes. It is written apart from the library's
// spring_runs.cpp on purpose: the baseline must not inherit the library's choices.
//
// When fewer than half of the springs are in chunks (the one- and two-element cases), rows
// of 4 doubles per node (x, y, z, 0) are faster: each spring end is one aligned 256-bit load,
// four springs at a time. The constructor picks the layout.

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

  [[nodiscard]] Counts counts() const { return {n_, springs_}; }
  void set_state(const State& s);
  [[nodiscard]] State state() const;
  void save();
  void restore();
  /// Forces at the current state, per mesh point (springs + gravity; fixed points included).
  [[nodiscard]] std::vector<double> forces();
  [[nodiscard]] double max_abs_position() const;

 private:
  void accumulate_springs();
  void accumulate_rows();
  void step_rows(double h);

  template <class T>
  using Vec = physics::AlignedVector<T>;
  struct Chunk {
    std::uint32_t i0, j0;
    std::uint8_t mask;
  };
  std::size_t n_ = 0, springs_ = 0;
  // Per axis, padded past the last node so that an 8-lane access may start at any node:
  // positions, velocities, the force accumulator (both ends of every spring), 1/m and g (0 on
  // fixed axes).
  std::array<Vec<double>, 3> x_, v_, f_, inv_mass_, g_;
  Vec<double> mass_;  // per node, for forces()
  std::array<double, 3> gravity_{};
  std::vector<Chunk> chunks_;        // in order of i0
  Vec<double> ck_, cl_, cg_;         // 8 per chunk; unused lanes k = 0, l = 1, γ = 0
  Vec<std::uint32_t> ri_, rj_;       // the springs in no chunk
  Vec<double> rk_, rl_, rg_;
  std::array<Vec<double>, 3> saved_x_, saved_v_;
  // The row layout (used instead of all the above when rows_ is set): 4 per node.
  bool rows_ = false;
  Vec<double> x4_, v4_, acc4_, inv_mass4_, g4_, saved_x4_, saved_v4_;
  Vec<std::uint32_t> i_, j_;
  Vec<double> k_, l_, gamma_;
};

}  // namespace sewn::bench::mss
