#pragma once
// The scene key `motion`: prescribed rigid motions of selected particles (the 2019 paper turns
// the frisbee's rim, drives the jellyfish's body and the anglerfish's head). Kept apart from
// scene.cpp so the scene layer only lists the key.
//
// A driven particle is a Dirichlet node: all its axes are fixed and, before every step, its
// velocity is set to (x(t + h) − x_now)/h, which every integrator keeps on fixed axes
// (NodeTable::set_velocity), so the step lands it exactly on the prescribed x(t + h)
// (NewtonEuler: q = q_n + h v_n on fixed axes; the MSS integrators: P ← P + hV with V kept).
// The trajectory depends on t alone, so a run resumed from a checkpoint drives the same
// positions as the uninterrupted one.

#include <cstdint>
#include <functional>
#include <limits>
#include <string>
#include <vector>

#include <Eigen/Core>
#include <nlohmann/json.hpp>

#include "sewn/apps/schema.hpp"
#include "sewn/physics/nodes.hpp"

namespace sewn::app {

struct Selector;

/// motion[k]: from `from` to `until`, the selection moves rigidly: with τ the time spent in the
/// entry so far, x(τ) = center + velocity·τ + R(axis, rate·τ)(x₀ − center), x₀ where the
/// particle was when the entry started. Outside [from, until] the entry holds its end pose.
struct MotionSpec {
  std::array<double, 3> velocity{0, 0, 0};  ///< m/s, translation
  Eigen::Vector3d axis{0, 0, 1};            ///< unit
  Eigen::Vector3d center{0, 0, 0};          ///< m, a point of the axis at τ = 0
  double rate = 0;                          ///< rad/s about axis (right hand)
  double from = 0;                          ///< s
  double until = std::numeric_limits<double>::infinity();  ///< s; infinite: to the end of the run
};

/// The schema of the `motion` array.
Field motion_schema();
/// Reads a validated `motion` array, each entry's selector into `where` (same order). Throws
/// SceneError naming "motion[k].key" for values the schema cannot express (until ≤ from, a zero
/// axis, an entry that moves nothing). O(entries).
std::vector<MotionSpec> read_motion(const nlohmann::json& j, const Field& schema, const std::string& file,
                                    std::vector<Selector>& where);

/// The driven particles of a run and their trajectories.
class MotionDriver {
 public:
  MotionDriver() = default;
  /// `nodes[k]`: the particles entry k drives. Fixes every one on all axes; x₀ is its position
  /// now. Throws SceneError (naming motion[k].where, and the particle by `name`, or its index
  /// if none) for a particle two entries drive over overlapping times. Entries driving one
  /// particle at disjoint times chain in time order.
  MotionDriver(std::vector<MotionSpec> specs, const std::vector<std::vector<physics::Index>>& nodes, physics::NodeTable& table,
               const std::string& file, const std::function<std::string(physics::Index)>& name = {});

  [[nodiscard]] bool empty() const { return driven_.empty(); }
  [[nodiscard]] std::size_t size() const { return driven_.size(); }
  /// The prescribed position of the i-th driven particle at time t (i < size()).
  [[nodiscard]] Eigen::Vector3d position(std::size_t i, double t) const;
  [[nodiscard]] physics::Index node(std::size_t i) const { return driven_[i].node; }
  /// Sets every driven particle's velocity so that a step of h from t ends on x(t + h). O(driven).
  void drive(physics::NodeTable& table, double t, double h) const;

 private:
  struct Driven {
    physics::Index node = 0;
    Eigen::Vector3d x0;
    std::vector<std::uint32_t> specs;  ///< in time order
  };
  std::vector<MotionSpec> specs_;
  std::vector<Driven> driven_;
};

}  // namespace sewn::app
