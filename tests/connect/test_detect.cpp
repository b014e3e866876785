// Detection of connections from a mesh's cells (detect.hpp): components (solids through faces,
// shells through manifold edges, rods through chain points) and, per pair of components, the
// highest-dimensional contact at each place — surface, curve or point — on small meshes whose
// answers are known by hand; the report's text; bad cells.

#include <stdexcept>
#include <string>

#include <doctest/doctest.h>

#include "sewn/connect/detect.hpp"

namespace test_detect {
namespace {

using sewn::connect::Body;
using sewn::connect::body_pair_index;
using sewn::connect::CellList;
using sewn::connect::ConnectionKind;
using sewn::connect::detect_connections;
using sewn::connect::FoundConnections;

std::uint32_t count(const FoundConnections& f, ConnectionKind k, Body a, Body b) {
  return f.counts[static_cast<std::size_t>(k)][static_cast<std::size_t>(body_pair_index(a, b))];
}

// Two tetrahedra sharing the face (1, 2, 3): one solid.
CellList block() {
  CellList c;
  c.add(Body::solid, {0, 1, 2, 3});
  c.add(Body::solid, {1, 2, 3, 4});
  return c;
}

TEST_CASE("detect: a fin along a block's edge is a curve, a mast hanging from it a point") {
  CellList c = block();
  c.add(Body::shell, {1, 2, 5});  // the fin: shares the edge (1, 2), which is on no face of its own with the block
  c.add(Body::shell, {2, 6, 5});
  c.add(Body::rod, {6, 7});  // the mast from the fin's far corner
  c.add(Body::rod, {7, 8});
  const FoundConnections f = detect_connections(c);
  CHECK(f.component_body.size() == 3);
  CHECK(f.component_of_cell[0] == f.component_of_cell[1]);
  CHECK(f.component_of_cell[2] == f.component_of_cell[3]);
  CHECK(f.component_of_cell[4] == f.component_of_cell[5]);
  CHECK(count(f, ConnectionKind::curve, Body::shell, Body::solid) == 1);
  CHECK(count(f, ConnectionKind::point, Body::shell, Body::solid) == 0);  // the edge's ends are covered by the curve
  CHECK(count(f, ConnectionKind::point, Body::rod, Body::shell) == 1);
  CHECK(f.total() == 2);
  CHECK(sewn::connect::connections_text(f) == "  point: 1 rod-shell\n  curve: 1 shell-solid\n");
}

TEST_CASE("detect: a shell on a solid's face is a surface connection, and nothing else between them") {
  CellList c = block();
  c.add(Body::shell, {0, 1, 2});  // a face of the first tet
  c.add(Body::shell, {0, 2, 9});  // and a triangle beyond it, sharing only the edge (0, 2) with the block
  const FoundConnections f = detect_connections(c);
  CHECK(count(f, ConnectionKind::surface, Body::shell, Body::solid) == 1);
  CHECK(count(f, ConnectionKind::curve, Body::shell, Body::solid) == 0);  // (0, 2) is an edge of the shared face
  CHECK(count(f, ConnectionKind::point, Body::shell, Body::solid) == 0);
  CHECK(f.total() == 1);
}

TEST_CASE("detect: three shells around one edge, rods meeting at a point, a rod along a solid's edge") {
  CellList c;
  c.add(Body::shell, {0, 1, 2});
  c.add(Body::shell, {0, 1, 3});
  c.add(Body::shell, {0, 1, 4});  // a non-manifold edge: three components
  FoundConnections f = detect_connections(c);
  CHECK(f.component_body.size() == 3);
  CHECK(count(f, ConnectionKind::curve, Body::shell, Body::shell) == 3);
  CHECK(f.total() == 3);

  CellList r;
  r.add(Body::rod, {0, 1});
  r.add(Body::rod, {1, 2});  // a chain through 1
  r.add(Body::rod, {2, 3});
  r.add(Body::rod, {2, 4});  // three segments at 2: three chains
  f = detect_connections(r);
  CHECK(f.component_body.size() == 3);
  CHECK(count(f, ConnectionKind::point, Body::rod, Body::rod) == 3);

  CellList s = block();
  s.add(Body::rod, {10, 0});
  s.add(Body::rod, {0, 4});  // through the block's interior? no: (0, 4) is not a tet edge
  s.add(Body::rod, {4, 11});
  f = detect_connections(s);
  CHECK(count(f, ConnectionKind::point, Body::rod, Body::solid) == 2);
  CHECK(count(f, ConnectionKind::curve, Body::rod, Body::solid) == 0);
  CellList t = block();
  t.add(Body::rod, {0, 1});  // along a tet edge
  t.add(Body::rod, {1, 4});
  f = detect_connections(t);
  CHECK(count(f, ConnectionKind::curve, Body::rod, Body::solid) == 2);
  CHECK(count(f, ConnectionKind::point, Body::rod, Body::solid) == 0);
}

TEST_CASE("detect: solids touching along an edge or at a point") {
  CellList c = block();
  c.add(Body::solid, {0, 1, 20, 21});  // shares the edge (0, 1) only
  c.add(Body::solid, {4, 30, 31, 32});  // shares the point 4 only
  const FoundConnections f = detect_connections(c);
  CHECK(f.component_body.size() == 3);
  CHECK(count(f, ConnectionKind::curve, Body::solid, Body::solid) == 1);
  CHECK(count(f, ConnectionKind::point, Body::solid, Body::solid) == 1);
  CHECK(f.total() == 2);
  CellList none;
  none.add(Body::shell, {0, 1, 2});
  CHECK(sewn::connect::connections_text(detect_connections(none)) == "  none: the components share no point\n");
}

TEST_CASE("detect: chain keys split a rod where a model splits it, giving a rod-rod point there") {
  // one straight line of three segments; keyed 1, 1, 2 (two groups in a scene): two rods
  CellList one, two;
  for (std::uint32_t k = 0; k < 3; ++k) {
    one.add(Body::rod, {k, k + 1});
    two.add(Body::rod, {k, k + 1}, k < 2 ? 1u : 2u);
  }
  const FoundConnections f1 = detect_connections(one), f2 = detect_connections(two);
  CHECK(f1.component_body.size() == 1);
  CHECK(f1.total() == 0);
  CHECK(f2.component_body.size() == 2);
  CHECK(count(f2, ConnectionKind::point, Body::rod, Body::rod) == 1);
  REQUIRE(f2.total() == 1);
  CHECK(f2.connections[0].points == std::vector<std::uint32_t>{2});
}

TEST_CASE("detect: bad cells are refused with what and where") {
  CellList c;
  CHECK_THROWS_WITH_AS(c.add(Body::shell, {0, 1}), "connect::CellList: a shell cell has 3 points, got 2 (cell 0)", std::invalid_argument);
  CHECK_THROWS_WITH_AS(c.add(Body::solid, {0, 1, 2, 1}), "connect::CellList: cell 0 repeats point 1", std::invalid_argument);
}

}  // namespace
}  // namespace test_detect
