#include <doctest/doctest.h>

#include <cmath>
#include <limits>

#include "io_test_util.hpp"
#include "sewn/io/cleanup.hpp"
#include "sewn/io/geometry.hpp"
#include "sewn/io/read.hpp"

namespace test_geometry {

using namespace sewn;
using namespace sewn::io;
using sewn::io::test::message_of;

namespace {

// One positively oriented cell of each volume type, in VTK order.
IndexedMesh unit_cell(CellType t) {
  IndexedMesh m;
  switch (t) {
    case CellType::tetrahedron:
      m.points = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
      m.add_cell(t, {0, 1, 2, 3});
      break;
    case CellType::hexahedron:
      m.points = {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}, {0, 0, 1}, {1, 0, 1}, {1, 1, 1}, {0, 1, 1}};
      m.add_cell(t, {0, 1, 2, 3, 4, 5, 6, 7});
      break;
    case CellType::prism:  // base (0,1,2) turning away from (3,4,5)
      m.points = {{0, 0, 0}, {0, 1, 0}, {1, 0, 0}, {0, 0, 1}, {0, 1, 1}, {1, 0, 1}};
      m.add_cell(t, {0, 1, 2, 3, 4, 5});
      break;
    default:  // pyramid: base (0,1,2,3) turning towards the apex
      m.points = {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}, {0.5, 0.5, 1}};
      m.add_cell(CellType::pyramid, {0, 1, 2, 3, 4});
  }
  return m;
}

// Signed volume from the outward face tables of mesh.hpp (divergence theorem on a fan of each
// face): an independent statement of what "positively oriented" means.
double face_volume(const IndexedMesh& m, std::uint32_t c) {
  const auto v = m.cell(c);
  double vol = 0;
  for (auto f : cell_faces(m.types[c])) {
    const auto& a = m.points[v[f[0]]];
    for (std::size_t k = 1; k + 1 < f.size(); ++k) {
      const auto& b = m.points[v[f[k]]];
      const auto& d = m.points[v[f[k + 1]]];
      vol += (a[0] * (b[1] * d[2] - b[2] * d[1]) - a[1] * (b[0] * d[2] - b[2] * d[0]) + a[2] * (b[0] * d[1] - b[1] * d[0])) / 6;
    }
  }
  return vol;
}

IndexedMesh mirrored(IndexedMesh m) {
  for (auto& p : m.points) p[2] = -p[2];
  return m;
}

}  // namespace

TEST_CASE("corner Jacobians agree with the outward face tables for every volume type") {
  for (CellType t : {CellType::tetrahedron, CellType::hexahedron, CellType::prism, CellType::pyramid}) {
    CAPTURE(to_string(t));
    const IndexedMesh m = unit_cell(t);
    CHECK(face_volume(m, 0) > 0);
    CHECK(min_scaled_jacobian(m, 0) > 0.1);
    CHECK_NOTHROW(check_mesh_geometry(m, "unit"));
    // a mirror image has the opposite orientation: negative volume, negative at every corner
    const IndexedMesh r = mirrored(m);
    CHECK(face_volume(r, 0) < 0);
    const auto msg = message_of<InvertedCellError>([&] { check_mesh_geometry(r, "mirror.msh"); });
    CHECK(msg.find(std::string("mirror.msh: cell 0 (") + to_string(t) + ") is inverted") == 0);
    CHECK(msg.find("points 0 (0, 0, -0)") != std::string::npos);
  }
}

TEST_CASE("the grid generators and their tetrahedral splits are all positive") {
  CHECK(find_geometry_issues(hex_grid(3, 2, 2)).empty());
  CHECK(find_geometry_issues(tet_grid(2, 2, 2, TetSplit::kuhn6)).empty());
  CHECK(find_geometry_issues(tet_grid(2, 2, 2, TetSplit::five)).empty());
  CHECK(find_geometry_issues(tri_grid(3, 3)).empty());
  CHECK(find_geometry_issues(quad_grid(3, 3)).empty());
  CHECK(find_geometry_issues(polyline_x(4)).empty());
}

TEST_CASE("inverted tetrahedron among good ones is named with its points") {
  IndexedMesh m = tet_grid(1, 1, 1, TetSplit::kuhn6);
  auto v = m.cell(3);
  std::vector<std::uint32_t> c(v.begin(), v.end());
  std::swap(m.conn[m.offsets[3] + 1], m.conn[m.offsets[3] + 2]);
  const auto err = [&] {
    try {
      check_mesh_geometry(m, "tets.vtk");
    } catch (const InvertedCellError& e) {
      return std::make_pair(std::string(e.what()), e.cell());
    }
    return std::make_pair(std::string(), 0u);
  }();
  CHECK(err.second == 3);
  CHECK(err.first.find("tets.vtk: cell 3 (tetrahedron) is inverted") == 0);
  const auto issues = find_geometry_issues(m, "tets.vtk");
  REQUIRE(issues.size() == 1);
  CHECK(issues[0].kind == GeometryProblem::inverted);
}

TEST_CASE("flat, collapsed and folded hexahedra are degenerate") {
  SUBCASE("zero volume: the top face pushed onto the bottom") {
    IndexedMesh m = unit_cell(CellType::hexahedron);
    for (std::size_t k = 4; k < 8; ++k) m.points[k][2] = 0;
    CHECK(message_of<DegenerateCellError>([&] { check_mesh_geometry(m, "flat"); }).find("flat: cell 0 (hexahedron) is degenerate") == 0);
  }
  SUBCASE("one corner pushed through the opposite face: positive volume, folded corner") {
    IndexedMesh m = unit_cell(CellType::hexahedron);
    m.points[6] = {0.1, 0.1, -0.5};
    CHECK(face_volume(m, 0) > 0);  // a volume test alone would not see this
    const auto msg = message_of<DegenerateCellError>([&] { check_mesh_geometry(m, "fold"); });
    CHECK(msg.find("not positive at local corner(s)") != std::string::npos);
  }
  SUBCASE("two vertices at the same place") {
    IndexedMesh m = unit_cell(CellType::hexahedron);
    m.points[5] = m.points[4];
    message_of<DegenerateCellError>([&] { check_mesh_geometry(m, "dup"); });
  }
  SUBCASE("a mildly sheared hexahedron is fine") {
    IndexedMesh m = unit_cell(CellType::hexahedron);
    for (std::size_t k = 4; k < 8; ++k) m.points[k][0] += 0.7;
    CHECK_NOTHROW(check_mesh_geometry(m, "shear"));
  }
}

TEST_CASE("degenerate 2D cells and segments; tolerance is relative to size") {
  IndexedMesh tri;
  tri.points = {{0, 0, 0}, {1, 0, 0}, {2, 0, 0}};
  tri.add_cell(CellType::triangle, {0, 1, 2});
  CHECK(message_of<DegenerateCellError>([&] { check_mesh_geometry(tri, "tri"); }).find("tri: cell 0 (triangle) is degenerate") == 0);
  IndexedMesh bowtie;
  bowtie.points = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {1, 1, 0}};
  bowtie.add_cell(CellType::quad, {0, 1, 2, 3});
  message_of<DegenerateCellError>([&] { check_mesh_geometry(bowtie, "bowtie"); });
  IndexedMesh seg;
  seg.points = {{0, 0, 0}, {1, 0, 0}, {1, 0, 0}};
  seg.add_cell(CellType::segment, {0, 1});
  seg.add_cell(CellType::segment, {1, 2});
  CHECK(message_of<DegenerateCellError>([&] { check_mesh_geometry(seg, "seg"); }).find("seg: cell 1 (segment)") == 0);
  // a micro-scale tetrahedron is as valid as a unit one
  IndexedMesh tiny = unit_cell(CellType::tetrahedron);
  for (auto& p : tiny.points)
    for (double& x : p) x *= 1e-9;
  CHECK_NOTHROW(check_mesh_geometry(tiny, "tiny"));
}

TEST_CASE("non-finite coordinates are reported first, with a cell using the point") {
  IndexedMesh m = hex_grid(2, 1, 1);
  m.points[2][1] = std::numeric_limits<double>::quiet_NaN();  // point (2, 0, 0): only in cell 1
  const auto msg = message_of<NonFiniteCoordinateError>([&] { check_mesh_geometry(m, "beam"); });
  CHECK(msg.find("beam: point 2 has a non-finite coordinate (2, nan, 0); it is used by cell 1 (hexahedron)") == 0);
  m.points.push_back({std::numeric_limits<double>::infinity(), 0, 0});
  const auto issues = find_geometry_issues(m, "beam");
  REQUIRE(issues.size() == 2);
  CHECK(issues[1].cell == GeometryError::no_cell);
  CHECK(issues[1].points == std::vector<std::uint32_t>{12});
}

TEST_CASE("indices out of range are a MeshError before any geometry is looked at") {
  IndexedMesh m = unit_cell(CellType::tetrahedron);
  m.conn[3] = 9;
  CHECK_THROWS_AS(check_mesh_geometry(m, "bad"), MeshError);
}

TEST_CASE("drop_embedded_cells removes boundary copies, keeps cells that are not faces or edges") {
  IndexedMesh m = hex_grid(2, 1, 1);
  m.add_cell(CellType::quad, {0, 1, 4, 3}, 7);     // a face of hexahedron 0 (bottom)
  m.add_cell(CellType::quad, {0, 1, 10, 9}, 8);    // a diagonal plane of hexahedron 0: not a face
  m.add_cell(CellType::segment, {0, 1}, 9);        // an edge of hexahedron 0
  m.add_cell(CellType::segment, {0, 4}, 9);        // a face diagonal: not an edge
  m.add_cell(CellType::triangle, {0, 1, 10}, 5);   // cuts through hexahedron 0: not a face
  CHECK(drop_embedded_cells(m) == 2);
  REQUIRE(m.num_cells() == 5);
  CHECK(m.types == std::vector<CellType>{CellType::hexahedron, CellType::hexahedron, CellType::quad,
                                         CellType::segment, CellType::triangle});
  CHECK(m.tags == std::vector<std::int32_t>{0, 0, 8, 9, 5});
  CHECK_NOTHROW(m.check_indices());
  // segments on the edge of a 2D cell go too
  IndexedMesh s = tri_grid(1, 1);
  s.add_cell(CellType::segment, {0, 1});
  CHECK(drop_embedded_cells(s) == 1);
  CHECK(s.num_cells() == 2);
}

TEST_CASE("drop_unused_points renumbers the cells") {
  MeshFile f = read_gmsh(test::data("mixed41.msh"));  // node tags 140 and 150 belong to no element
  const IndexedMesh before = f.mesh;
  const auto map = drop_unused_points(f.mesh);
  CHECK(f.mesh.num_points() == 13);
  CHECK(map[13] == 0xffffffffu);
  CHECK(map[14] == 0xffffffffu);
  for (std::uint32_t c = 0; c < before.num_cells(); ++c)
    for (std::size_t k = 0; k < before.cell(c).size(); ++k)
      CHECK(f.mesh.points[f.mesh.cell(c)[k]] == before.points[before.cell(c)[k]]);
}

}  // namespace test_geometry
