#pragma once
// SpringRuns: the springs term's force path for springs that come in runs, i.e. spring q of a
// run joins nodes (i0 + q, j0 + q). Grids and structured generators number their nodes so
// that almost every spring is in one (a box of N³ hexahedra: all of them), and then eight
// springs are one chunk whose node values are contiguous in per-axis arrays: plain vector
// loads and stores, no gathers, no shuffles. Springs in no chunk (re-attached by a cut, added
// later, or from an unstructured mesh) form the rest list, processed one by one.
//
// The plan is built once (O(m log m)) and then kept up to date by O(1) edits as springs are
// added, removed, re-attached or re-parametrised, so a cut does not pay a rebuild; the term
// rebuilds it when the rest list has grown by an eighth of the springs. Internal to
// Springs (detail): its only user, and the one that keeps it in sync.

#include <cstdint>
#include <span>
#include <vector>

#include "sewn/physics/aligned.hpp"
#include "sewn/physics/types.hpp"

namespace sewn::physics {
class StabilityRows;
}

namespace sewn::physics::detail {

/// The spring arrays as the plan reads them (one entry per spring slot).
struct SpringArrays {
  const Index* ni;
  const Index* nj;
  const double* k;
  const double* l;
  const double* g;
  const std::uint8_t* alive;
  Index count;
};

/// Which damping the kernel applies (mirrors SpringDamping without depending on springs.hpp).
enum class RunDamping : std::uint8_t { none, viscous, stiffness_proportional };

class SpringRuns {
 public:
  static constexpr int lanes = 8;

  /// Rebuilds the plan from every live spring. O(m log m).
  void rebuild(const SpringArrays& a);
  /// Forgets the plan; the next needs_rebuild() is true. O(1).
  void invalidate() { built_ = false; }
  /// True if there is no plan, or the rest list has grown by an eighth of the live springs
  /// since it was built (so rebuilds cost O(log m) per edit, amortised).
  [[nodiscard]] bool needs_rebuild() const;
  /// True if at least half of the live springs are in chunks, and chunks are at least 3/4
  /// full on average; otherwise the row path is faster (measured: a 4³ grid, whose runs are 4
  /// or 5 springs long, steps faster on rows).
  [[nodiscard]] bool worthwhile() const {
    return built_ && 2 * chunked_ >= live_ && 4 * std::size_t{chunked_} >= 3 * lanes * chunks_.size();
  }
  [[nodiscard]] Index num_chunked() const { return chunked_; }
  [[nodiscard]] Index num_rest() const { return static_cast<Index>(rest_.size()); }
  /// The springs in no chunk (some may be dead since they were listed), each listed once.
  [[nodiscard]] std::span<const Index> rest() const { return rest_; }

  // ---- O(1) edits, called by Springs after it changed its own arrays (no-ops without a plan)
  /// Spring slot s was added (or reused): it joins the rest list.
  void on_added(Index s);
  /// Spring s was removed: its lane is switched off (a rest entry is skipped while it is dead).
  void on_removed(Index s);
  /// Spring s joins other nodes: it leaves its chunk for the rest list.
  void on_endpoints_changed(Index s);
  /// Spring s has new k, l, γ: its lane copy follows.
  void on_parameters_changed(Index s, double k, double l, double g);
  /// Every spring's parameters may have changed: lane copies are refreshed. O(chunks).
  void refresh_parameters(const SpringArrays& a);

  /// Sets (accumulate = false) or adds the spring forces at x, v (3n each, node-major) into
  /// f (3n). β is the Rayleigh factor (stiffness_proportional only). O(n + m).
  void forces(const SpringArrays& a, RunDamping damping, double beta, std::span<const double> x,
              std::span<const double> v, std::span<double> f, bool accumulate, Index n) const;
  /// Sets `energy` to Σ ½ k (|xj − xi| − l)² over the live springs at x (3n), eight chunked
  /// springs at a time, the rest list one by one. Returns false, setting nothing, where there is
  /// no vector kernel (a build without AVX-512). O(n + m).
  bool potential_energy(const SpringArrays& a, std::span<const double> x, Index n, double& energy) const;
  /// Adds the stable-step rows of the chunked springs at x (3n) to rows, eight springs at a
  /// time; the rest list is the caller's. Returns false, adding nothing, where there is no
  /// vector kernel (a build without AVX-512) or the rows fold slaves. O(n + chunks).
  bool stability_rows(RunDamping damping, double beta, std::span<const double> x, Index n, StabilityRows& rows) const;

 private:
  struct Chunk {
    Index i0, j0;  // lane q joins nodes i0 + q and j0 + q
  };
  // Splits the nodes into `parts` ranges for forces() (node_at_, chunk_at_), or into one if a
  // range would be shorter than a seam; returns the count used.
  int plan_ranges(int parts, Index n) const;
  // Sizes soa_ for n nodes and `arrays` per-axis arrays, keeping it if it fits.
  void ensure_arrays(Index n, std::size_t arrays) const;
  void ensure_lane_index(Index count);
  void to_rest(Index s);
  // Switches off spring s's lane, if it has one.
  void leave_chunk(Index s);

  bool built_ = false;
  std::vector<Chunk> chunks_;
  std::vector<std::uint8_t> mask_;          // live lanes of each chunk
  AlignedVector<double> k_, l_, g_;         // lanes · chunks, padding lanes k = 0, l = 1, γ = 0
  std::vector<Index> spring_;               // lane -> spring, or invalid_index
  std::vector<std::uint32_t> lane_of_;      // spring -> chunk · 8 + lane, or none
  std::vector<std::uint8_t> in_rest_;       // spring -> listed in rest_
  std::vector<Index> rest_;
  std::vector<std::size_t> reach_;  // per block of chunks: nodes below it are read up to it
  std::vector<Index> floor_;        // per block: the lowest node a later block touches
  // How far past the start of a thread's node range the springs of the ranges before it add
  // forces: the largest j0 − i0 of a chunk, plus its lanes, rounded up to 8 nodes.
  std::size_t overhang_ = 0;
  // forces()'s ranges: thread t owns nodes [node_at_[t], node_at_[t + 1]) and the chunks whose
  // lower node is among them, chunks [chunk_at_[t], chunk_at_[t + 1]).
  mutable std::vector<std::size_t> node_at_, chunk_at_;
  std::size_t rest_at_build_ = 0;
  Index chunked_ = 0, live_ = 0;
  // Per-axis node arrays: x y z, vx vy vz, and the force accumulators fx fy fz, one such set
  // per thread of forces(); the accumulators are all zero between calls.
  mutable AlignedVector<double> soa_;
  mutable std::size_t stride_ = 0;
};

}  // namespace sewn::physics::detail
