#pragma once
// The part every connection force term shares: a stencil's DOFs (node axes and System angles)
// read from a state, its gradient scattered into forces, its Hessian into the block matrix
// (angles in the rows AngleLayout gives them), its node pairs, its node checks and renumbering.
// PointConnections and CurveConnections each hold one StencilDofs per element.

#include <functional>
#include <span>
#include <utility>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "sewn/physics/force_term.hpp"

namespace sewn::connect {

/// The rule under topology edits, asked per connection c (in order) by a term's follow_nodes():
/// return false to remove it, or true after filling `renames` with (old node, new node) pairs
/// (each old node to one new node) for the nodes it now has.
using NodeDecision = std::function<bool(physics::Index c, std::vector<std::pair<physics::Index, physics::Index>>& renames)>;

class StencilDofs {
 public:
  /// Appends the three axes of `node`.
  void add_node(physics::Index node);
  /// Appends System angle `angle`.
  void add_angle(physics::Index angle);
  [[nodiscard]] std::size_t size() const { return dofs_.size(); }

  /// The stencil's values at s. Throws physics::InputError naming `owner` if an angle is not in
  /// the state (an integrator that does not integrate angles).
  [[nodiscard]] Eigen::VectorXd gather(const physics::StateView& s, const std::string& owner) const;
  /// f −= gradient, DOF by DOF (angles after the 3n positions, where present in f).
  void subtract_gradient(const Eigen::VectorXd& gradient, const physics::StateView& s, std::span<double> f) const;
  /// The distinct block-row pairs the stencil couples.
  void collect_pairs(const physics::AngleLayout& layout, std::vector<physics::NodePair>& out) const;
  /// Caches where the stencil's blocks sit in the bound pattern.
  void bind(const physics::AngleLayout& layout, const physics::BlockMatrix& pattern);
  /// Performs req with the stencil Hessian H of the energy (∂F/∂x = −H).
  void add_hessian(const Eigen::MatrixXd& H, const physics::AngleLayout& layout, const physics::JacobianRequest& req) const;
  /// Throws physics::InputError naming `owner` if a node is removed or out of range.
  void check_nodes(const physics::NodeTable& nodes, const std::string& owner) const;
  void remap_nodes(std::span<const physics::Index> old_to_new);
  /// True if a node of the stencil is removed (or out of range) in `nodes`.
  [[nodiscard]] bool touches_removed(const physics::NodeTable& nodes) const;

 private:
  struct Dof {
    bool angle = false;
    physics::Index id = 0;  // node or angle
    int axis = 0;           // for a node
  };
  [[nodiscard]] static physics::Index block_row(const Dof& d, const physics::AngleLayout& layout) {
    return d.angle ? layout.block(d.id) : d.id;
  }
  [[nodiscard]] static int component(const Dof& d, const physics::AngleLayout& layout) {
    return d.angle ? layout.component(d.id) : d.axis;
  }
  std::vector<Dof> dofs_;
  std::vector<physics::Index> blocks_;  // distinct block rows (set by bind)
  std::vector<int> block_of_;           // per DOF: its index in blocks_
  std::vector<physics::Index> slots_;   // blocks_ × blocks_
};

}  // namespace sewn::connect
