// Node table: adding, duplicating (cut), masses, fixed axes, removal and compaction through
// the System (terms renumbered), input checks; the block pattern.
#include <doctest/doctest.h>

#include <cmath>

#include "sewn/physics/constraints/slave_nodes.hpp"
#include "sewn/physics/physics.hpp"

namespace test_nodes {

using namespace sewn::physics;
using Eigen::Vector3d;

TEST_CASE("node table: add, duplicate, masses, fixed axes and the 3n views") {
  NodeTable nodes;
  const Index a = nodes.add({1, 2, 3}, {0.1, 0.2, 0.3}, 2.0);
  const Index b = nodes.add({4, 5, 6}, {0, 0, 0}, 4.0);
  CHECK(a == 0);
  CHECK(b == 1);
  CHECK(nodes.size() == 2);
  CHECK(nodes.positions_flat().size() == 6);
  CHECK(nodes.positions().col(1) == Vector3d(4, 5, 6));
  CHECK(nodes.x()[4] == 5.0);
  nodes.fix(a, axis_y);
  CHECK(nodes.fixed(a) == axis_y);
  CHECK(nodes.velocity(a) == Vector3d(0.1, 0.0, 0.3));  // fixing zeroes the fixed axis' velocity
  CHECK(nodes.inverse_mass_dof()[0] == 0.5);
  CHECK(nodes.inverse_mass_dof()[1] == 0.0);
  CHECK(nodes.num_fixed_nodes() == 1);
  const Index c = nodes.duplicate(a);
  CHECK(c == 2);
  CHECK(nodes.position(c) == nodes.position(a));
  CHECK(nodes.velocity(c) == nodes.velocity(a));
  CHECK(nodes.fixed(c) == axis_y);
  CHECK(nodes.num_fixed_nodes() == 2);
  const auto before = nodes.parameter_version();
  nodes.set_mass(c, 1.0);
  CHECK(nodes.parameter_version() > before);
  CHECK(nodes.inverse_mass_dof()[6] == 1.0);
  nodes.unfix(a);
  CHECK(nodes.fixed(a) == no_axes);
  CHECK(nodes.inverse_mass_dof()[1] == 0.5);
  CHECK(nodes.num_fixed_nodes() == 1);
}

TEST_CASE("node versions are unique across tables: a kept lumped mass does not survive a table assigned in its place") {
  // Two tables changed the same way, with different masses: counters of their own would give
  // them equal versions, and the slaves' kept inverse masses (keyed by the table's address and
  // versions) would outlive `a = b`.
  NodeTable a, b;
  for (Index i = 0; i < 3; ++i) {
    a.add({static_cast<double>(i), 0, 0}, {0, 0, 0}, 1.0);
    b.add({static_cast<double>(i), 0, 0}, {0, 0, 0}, 2.0);
  }
  CHECK((a.topology_version() != b.topology_version() || a.parameter_version() != b.parameter_version()));
  SlaveNode mid;  // node 1 halfway between nodes 0 and 2
  mid.node = 1;
  mid.master = {0, 2, invalid_index, invalid_index};
  mid.weight = {0.5, 0.5, 0, 0};
  mid.masters = 2;
  SlaveNodes slaves;
  slaves.set({mid});
  const double before = slaves.inverse_mass_dof(a)[0];
  CHECK(before == 1 / 1.5);  // a master's own mass and half the slave's
  a = b;
  const double after = slaves.inverse_mass_dof(a)[0];
  CHECK(after == 1 / 3.0);
  const NodeTable copy = a;  // a copy shares its versions with its content
  CHECK(copy.topology_version() == a.topology_version());
  CHECK(slaves.inverse_mass_dof(copy)[0] == 1 / 3.0);
}

TEST_CASE("node table refuses bad input, naming the node") {
  NodeTable nodes;
  CHECK_THROWS_WITH_AS(nodes.add({0, 0, 0}, {0, 0, 0}, -1.0), doctest::Contains("mass of node 0"), InputError);
  CHECK_THROWS_AS(nodes.add({0, 0, 0}, {0, 0, 0}, 0.0), InputError);
  CHECK_THROWS_WITH_AS(nodes.add({std::nan(""), 0, 0}, {0, 0, 0}, 1.0), doctest::Contains("position of new node 0"),
                       InputError);
  CHECK(nodes.size() == 0);
  nodes.add({0, 0, 0}, {0, 0, 0}, 1.0);
  CHECK_THROWS_WITH_AS((void)nodes.position(3), doctest::Contains("node 3 out of range"), InputError);
  CHECK_THROWS_AS(nodes.set_mass(0, std::nan("")), InputError);
  CHECK_THROWS_AS(nodes.set_velocity(0, {INFINITY, 0, 0}), InputError);
  CHECK_THROWS_AS(nodes.fix(0, 8), InputError);
}

TEST_CASE("removal and compaction renumber nodes and springs together") {
  System sys;
  for (int i = 0; i < 5; ++i) sys.nodes().add({double(i), 0, 0}, {0, 0, 0}, 1.0 + i);
  Springs& sp = sys.add<Springs>();
  const Index s01 = sp.add(0, 1, 1, 1);
  const Index s12 = sp.add(1, 2, 1, 1);
  const Index s34 = sp.add(3, 4, 1, 1);
  sys.refresh();
  sys.nodes().remove(2);
  CHECK_FALSE(sys.nodes().is_alive(2));
  CHECK(sys.nodes().num_alive() == 4);
  // A spring still uses node 2: stepping or compacting is refused, nothing changes.
  CHECK_THROWS_WITH_AS(sys.refresh(), doctest::Contains("removed node 2"), InputError);
  CHECK_THROWS_AS(sys.compact_nodes(), InputError);
  CHECK(sys.nodes().size() == 5);
  sp.remove(s12);
  const auto map = sys.compact_nodes();
  CHECK(map == std::vector<Index>{0, 1, invalid_index, 2, 3});
  CHECK(sys.nodes().size() == 4);
  CHECK(sys.nodes().mass(2) == 4.0);
  CHECK(sp.node_i(s34) == 2);
  CHECK(sp.node_j(s34) == 3);
  CHECK(sp.node_j(s01) == 1);
  CHECK(sys.matrix().size() == 4);
  CHECK(sys.matrix().find(2, 3) != invalid_index);
}

TEST_CASE("block pattern: symmetric pairs, merged duplicates, diagonal always present") {
  BlockMatrix m;
  const std::vector<NodePair> pairs = {{0, 2}, {2, 0}, {1, 2}, {0, 2}};
  m.build_pattern(4, pairs);
  CHECK(m.num_blocks() == 4 + 4);
  CHECK(m.find(0, 2) != invalid_index);
  CHECK(m.find(2, 0) != invalid_index);
  CHECK(m.find(2, 1) != invalid_index);
  CHECK(m.find(0, 1) == invalid_index);
  CHECK(m.find(3, 3) == m.diagonal(3));
  m.block(m.find(0, 2)) = Eigen::Matrix3d::Identity() * 2;
  m.block(m.diagonal(2)) = Eigen::Matrix3d::Identity();
  std::vector<double> x(12, 1.0), y(12, 0.0);
  m.multiply(x, y);
  CHECK(y[0] == 2.0);
  CHECK(y[6] == 1.0);
  CHECK(y[3] == 0.0);
  const auto version = m.pattern_version();
  CHECK_THROWS_AS(m.build_pattern(2, pairs), InputError);
  m.build_pattern(3, std::vector<NodePair>{{0, 1}});
  CHECK(m.pattern_version() > version);
}

TEST_CASE("gravity and mass damping: per-node forces, energy and Jacobian") {
  System sys;
  for (int i = 0; i < 7; ++i)  // 7: the four-node vector blocks plus a tail
    sys.nodes().add({0.1 * i, -0.2 * i, 0.3}, {1.0 + i, -2.0, 0.5 * i}, 1.0 + 0.25 * i);
  const Vector3d g(0.5, -1.0, -9.81);
  sys.add<Gravity>(g);
  sys.add<MassDamping>(0.7);
  sys.compute_forces();
  for (Index i = 0; i < 7; ++i) {
    const double m = sys.nodes().mass(i);
    const Vector3d expect = m * g - 0.7 * m * sys.nodes().velocity(i);
    CHECK((sys.nodes().force(i) - expect).norm() <= 1e-15 * expect.norm());
  }
  double v = 0;
  for (Index i = 0; i < 7; ++i) v -= sys.nodes().mass(i) * g.dot(sys.nodes().position(i));
  CHECK(sys.potential_energy() == doctest::Approx(v).epsilon(1e-15));
  CHECK(sys.potential_energy(EnergyKind::external) == doctest::Approx(v).epsilon(1e-15));
  CHECK(sys.potential_energy(EnergyKind::internal) == 0.0);
  sys.refresh();
  sys.matrix().set_zero();
  JacobianRequest r;
  r.matrix = &sys.matrix();
  r.cv = 2.0;
  sys.add_jacobians(r);
  CHECK(sys.matrix().block(sys.matrix().diagonal(3)).isApprox(-2.0 * 0.7 * sys.nodes().mass(3) * Eigen::Matrix3d::Identity()));
}

}  // namespace test_nodes
