// Issue 17, inversion: inverted hexahedra and tetrahedra are counted against their rest
// orientation; a rigid rotation inverts nothing and a reflection inverts everything (the region
// 10⁶ times softer than the block it carries, turned inside out under gravity, is in
// test_volume_term.cpp with the term that prevents it).
#include <doctest/doctest.h>

#include <memory>
#include <vector>

#include <Eigen/Geometry>

#include "sewn/physics/mss_model.hpp"
#include "sewn/physics/solids/inversion.hpp"

namespace test_inversion {

using namespace sewn;
using namespace sewn::physics;
using Eigen::Vector3d;

TEST_CASE("inverted elements: none under a rigid rotation, all under a reflection, one when a corner is pushed through") {
  for (bool tets : {false, true}) {
    CAPTURE(tets);
    const GridSpec g{{0.1, 0.1, 0.1}, {}};
    MssModel<3> m(tets ? tet_grid(2, 2, 2, TetSplit::kuhn6, g) : hex_grid(2, 2, 2, g), {{1e6, 0.3, 1000}}, {});
    NodeTable& n = m.nodes();
    CHECK(count_inverted(m).elements == 0);
    const Eigen::Matrix3d R = Eigen::AngleAxisd(3.0, Vector3d(1, 2, -0.5).normalized()).toRotationMatrix();
    for (Index i = 0; i < n.size(); ++i) n.set_position(i, R * m.rest_position(i));
    CHECK(count_inverted(m).elements == 0);
    for (Index i = 0; i < n.size(); ++i) n.set_position(i, m.rest_position(i).cwiseProduct(Vector3d(-1, 1, 1)));
    CHECK(count_inverted(m).elements == m.num_live_elements());
    InversionMonitor monitor;  // the same, with corners kept between calls
    CHECK(monitor.count(m).elements == m.num_live_elements());
    for (Index i = 0; i < n.size(); ++i) n.set_position(i, R * m.rest_position(i));
    CHECK(monitor.count(m).elements == 0);
    // the corner node at the origin pushed through the opposite faces of its one element
    for (Index i = 0; i < n.size(); ++i) n.set_position(i, m.rest_position(i));
    const Index corner = m.node_of_point(0);
    n.set_position(corner, Vector3d(0.15, 0.15, 0.15));
    const InversionCount c = count_inverted(m);
    CHECK(c.elements >= 1);
    CHECK(c.first != invalid_index);
  }
}

TEST_CASE("a mirror-image rest mesh is refused, naming the cell") {
  for (bool tets : {false, true}) {
    CAPTURE(tets);
    const GridSpec g{{0.1, 0.1, 0.1}, {}};
    IndexedMesh mesh = tets ? tet_grid(2, 1, 1, TetSplit::kuhn6, g) : hex_grid(2, 1, 1, g);
    CHECK_NOTHROW(MssModel<3>(mesh, {{1e6, 0.3, 1000}}, {}));
    for (auto& q : mesh.points) q[0] = -q[0];
    CHECK_THROWS_WITH_AS(MssModel<3>(mesh, {{1e6, 0.3, 1000}}, {}), doctest::Contains("cell 0 "), InputError);
    CHECK_THROWS_WITH_AS(MssModel<3>(mesh, {{1e6, 0.3, 1000}}, {}), doctest::Contains("inside out"), InputError);
  }
}

}  // namespace test_inversion
