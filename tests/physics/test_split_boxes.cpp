// Issue 17, elongated cells: hexahedra too elongated for Baudet's stiffness split into
// near-cubes (physics/split_boxes). The split mesh conforms (shared edge and face points made
// once), keeps the volume and gives valid Baudet boxes; a cell of another type on a split edge
// is refused by name; and the static tip of the 1 m × 0.1 m × 0.1 m cantilever (E = 100 MPa)
// meshed with 10:1, 5:1 and 2.5:1 boxes is the cube-meshed beam's to within 10 %.
#include <doctest/doctest.h>

#include <cmath>
#include <vector>

#include <Eigen/SparseCholesky>

#include "helpers.hpp"
#include "sewn/physics/cell_input_error.hpp"
#include "sewn/physics/mss_model.hpp"
#include "sewn/physics/split_boxes.hpp"
#include "sewn/physics/stiffness.hpp"

namespace test_split_boxes {

using namespace sewn;
using namespace sewn::physics;

namespace split_boxes_test {

double total_volume(const IndexedMesh& mesh) {
  double v = 0;
  for (std::uint32_t c = 0; c < mesh.num_cells(); ++c) {
    const auto len = box_axis_lengths(mesh, c);
    v += len[0] * len[1] * len[2];
  }
  return v;
}

// Static tip deflection (mean downward displacement of the x = 1 m points) of the cantilever
// meshed by `mesh`, clamped at x = 0, under gravity: Newton on the exact tangent, each step
// solved by a sparse LDLᵀ, until the step is below 1e-12 m.
double static_tip(const IndexedMesh& mesh) {
  MssOptions o;
  o.damping = DampingModel::none;
  MssModel<3> m(mesh, {{100e6, 0.3, 1000}}, {}, o);
  NodeTable& nodes = m.nodes();
  for (Index i = 0; i < nodes.size(); ++i)
    if (m.rest_position(i).x() <= 1e-9) nodes.fix(i);
  const Eigen::Index n3 = 3 * Eigen::Index{nodes.size()};
  Eigen::VectorXd free_dof(n3);
  for (Index i = 0; i < nodes.size(); ++i)
    for (int a = 0; a < 3; ++a) free_dof[3 * Eigen::Index{i} + a] = (nodes.fixed(i) >> a) & 1u ? 0.0 : 1.0;
  const JacobianOptions exact{false, false, false};
  for (int it = 0; it < 30; ++it) {
    const Eigen::VectorXd f = test::forces(m.system());
    (void)test::assembled(m.system(), 1.0, 0.0, exact);
    Eigen::SparseMatrix<double> K = free_dof.asDiagonal() * (-m.system().matrix().to_sparse()) * free_dof.asDiagonal();
    for (Eigen::Index k = 0; k < n3; ++k)
      if (free_dof[k] == 0) K.coeffRef(k, k) = 1.0;
    Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>> ldlt(K);
    REQUIRE(ldlt.info() == Eigen::Success);
    const Eigen::VectorXd dx = ldlt.solve(Eigen::VectorXd(free_dof.asDiagonal() * f));
    auto x = nodes.x();
    for (Eigen::Index k = 0; k < n3; ++k) x[k] += dx[k];
    if (dx.cwiseAbs().maxCoeff() < 1e-12) break;
  }
  double sum = 0;
  int count = 0;
  for (Index i = 0; i < nodes.size(); ++i)
    if (m.rest_position(i).x() >= 1.0 - 1e-9) {
      sum += m.rest_position(i).z() - nodes.position(i).z();
      ++count;
    }
  return sum / count;
}

}  // namespace split_boxes_test

TEST_CASE("split boxes: 10:1 boxes side by side become the grid of cubes, conforming, the volume kept") {
  // four 1 × 0.1 × 0.1 boxes in a row along y share their long edges: one asks, all are split
  const IndexedMesh boxes = hex_grid(1, 4, 1, {{1.0, 0.1, 0.1}, {}});
  const std::vector<std::uint8_t> wanted{1, 0, 0, 0};
  const BoxSplit s = split_boxes(boxes, wanted, "row");
  CHECK(s.asked == 1);
  CHECK(s.split == 4);
  CHECK(s.mesh.num_cells() == 40);
  CHECK(s.mesh.num_points() == 11 * 5 * 2);  // shared points made once: the 10×4×1 grid's
  CHECK(split_boxes_test::total_volume(s.mesh) == doctest::Approx(0.04).epsilon(1e-12));
  for (std::uint32_t c = 0; c < s.mesh.num_cells(); ++c) {
    CHECK(s.source_cell[c] == c / 10);
    const auto len = box_axis_lengths(s.mesh, c);
    CHECK(len[0] == doctest::Approx(0.1));
    CHECK(baudet_box(1e6, 0.3, len[0], len[1], len[2]).valid());
  }
  // the model accepts it (the refuse policy), with the cube grid's springs
  CHECK(split_boxes(boxes, std::vector<std::uint8_t>{0, 0, 0, 0}, "row").split == 0);
  MssModel<3> split(s.mesh, {{1e6, 0.3, 1000}}, {});
  MssModel<3> cubes(hex_grid(10, 4, 1, {{0.1, 0.1, 0.1}, {}}), {{1e6, 0.3, 1000}}, {});
  CHECK(split.springs().size() == cubes.springs().size());
  CHECK(split.map().validate().ok());
}

TEST_CASE("split boxes: a 2.5:1 block and its neighbour across a shared face split alike; a tetrahedron on a split edge is refused") {
  // two 0.25 × 0.1 × 0.1 boxes side by side along y: both split 3 ways along x
  IndexedMesh two = hex_grid(1, 2, 1, {{0.25, 0.1, 0.1}, {}});
  const BoxSplit s = split_boxes(two, std::vector<std::uint8_t>{1, 0}, "pair");
  CHECK(s.split == 2);
  CHECK(s.mesh.num_cells() == 6);
  CHECK(s.mesh.num_points() == 4 * 3 * 2);  // the 3×2×1 grid's points
  CHECK(split_boxes_test::total_volume(s.mesh) == doctest::Approx(0.005).epsilon(1e-12));
  MssModel<3> model(s.mesh, {{1e6, 0.3, 1000}}, {});
  MssModel<3> grid(hex_grid(3, 2, 1, {{0.25 / 3, 0.1, 0.1}, {}}), {{1e6, 0.3, 1000}}, {});
  CHECK(model.map().validate().ok());
  CHECK(model.springs().size() == grid.springs().size());  // the shared face's points and edges made once
  // a tetrahedron on the edge (0, 1), which the split cuts
  IndexedMesh mixed = hex_grid(1, 1, 1, {{1.0, 0.1, 0.1}, {}});
  mixed.points.push_back({0.5, 0.05, -0.2});
  mixed.add_cell(CellType::tetrahedron, {0, 1, 8, 3});
  CHECK_THROWS_WITH_AS((void)split_boxes(mixed, std::vector<std::uint8_t>{1, 0}, "mixed.msh"),
                       doctest::Contains("mixed.msh: cell 1 (tetrahedron)"), InputError);
  // and why: which hexahedron asked, how elongated it is, how the edge would be cut
  CHECK_THROWS_WITH_AS((void)split_boxes(mixed, std::vector<std::uint8_t>{1, 0}, "mixed.msh"),
                       doctest::Contains("cut into 10 pieces because the hexahedron cell 0, 10:1, is too elongated"), InputError);
  // the cells and points apart, for a caller that names them as its files do
  try {
    (void)split_boxes(mixed, std::vector<std::uint8_t>{1, 0}, "mixed.msh");
    FAIL("no error");
  } catch (const CellInputError& e) {
    const auto& refs = e.message().refs();
    REQUIRE(refs.size() == 4);
    CHECK((refs[0].kind == IndexedMessage::Ref::Kind::cell && refs[0].index == 1));
    CHECK((refs[1].kind == IndexedMessage::Ref::Kind::point && refs[1].index == 0));
    CHECK((refs[2].kind == IndexedMessage::Ref::Kind::point && refs[2].index == 1));
    CHECK((refs[3].kind == IndexedMessage::Ref::Kind::cell && refs[3].index == 0));
    CHECK_MESSAGE(std::string(e.what()).find("shares the edge from point 0 to point 1 with hexahedra split") != std::string::npos, e.what());
  }
}

TEST_CASE("split boxes: the cantilever's static tip at 10:1, 5:1 and 2.5:1 boxes is the cube-meshed beam's to within 10 %") {
  // 4 cells through the thickness; the cube-meshed beam is 40×4×4 (PHYSICS_NOTES §4: 12.87 mm)
  const double cubes = split_boxes_test::static_tip(hex_grid(40, 4, 4, {{0.025, 0.025, 0.025}, {}}));
  for (const std::uint32_t nx : {4u, 8u, 16u}) {
    const double aspect = (1.0 / nx) / 0.025;
    CAPTURE(aspect);
    const IndexedMesh boxes = hex_grid(nx, 4, 4, {{1.0 / nx, 0.025, 0.025}, {}});
    const BoxSplit s = split_boxes(boxes, std::vector<std::uint8_t>(boxes.num_cells(), 1), "beam");
    const double tip = split_boxes_test::static_tip(s.mesh);
    MESSAGE(aspect << ":1 boxes, split into " << s.mesh.num_cells() / boxes.num_cells() << " each: tip " << tip * 1e3
                   << " mm against " << cubes * 1e3 << " mm meshed with cubes (" << (tip / cubes - 1) * 100 << " %)");
    CHECK(std::abs(tip / cubes - 1) < 0.10);
  }
}

}  // namespace test_split_boxes
