// Surface files (OFF, OBJ, STL) and their voxelization: exact cell sets on shapes whose inside
// is known in closed form, every format giving the same cells, bad files refused by name.
#include <doctest/doctest.h>

#include <array>
#include <cmath>
#include <cstring>
#include <string>
#include <vector>

#include "io_test_util.hpp"
#include "sewn/io/surface.hpp"

namespace test_surface {

using namespace sewn;
using namespace sewn::io;
using sewn::io::test::message_of;
using sewn::io::test::TempDir;

namespace surface_test {

// The 8 corners of the box [0, sx] x [0, sy] x [0, sz] and its 6 faces as quads, outward.
const std::array<std::array<int, 4>, 6> box_faces{{{0, 3, 2, 1}, {4, 5, 6, 7}, {0, 1, 5, 4}, {2, 3, 7, 6}, {1, 2, 6, 5}, {0, 4, 7, 3}}};
std::vector<Point3> box_corners(double sx, double sy, double sz) {
  return {{0, 0, 0}, {sx, 0, 0}, {sx, sy, 0}, {0, sy, 0}, {0, 0, sz}, {sx, 0, sz}, {sx, sy, sz}, {0, sy, sz}};
}
std::string box_off(double sx, double sy, double sz) {
  std::string s = "OFF\n8 6 0\n";
  for (const auto& p : box_corners(sx, sy, sz)) s += std::to_string(p[0]) + " " + std::to_string(p[1]) + " " + std::to_string(p[2]) + "\n";
  for (const auto& f : box_faces) s += "4 " + std::to_string(f[0]) + " " + std::to_string(f[1]) + " " + std::to_string(f[2]) + " " + std::to_string(f[3]) + "\n";
  return s;
}

// The octahedron |x| + |y| + |z| <= 1: 6 vertices, 8 triangles.
Surface octahedron() {
  Surface s;
  s.points = {{1, 0, 0}, {-1, 0, 0}, {0, 1, 0}, {0, -1, 0}, {0, 0, 1}, {0, 0, -1}};
  for (std::uint32_t x : {0u, 1u})
    for (std::uint32_t y : {2u, 3u})
      for (std::uint32_t z : {4u, 5u}) s.triangles.push_back({x, y, z});
  return s;
}

double cell_volume(const IndexedMesh& m) {
  const auto c = m.cell(0);
  return std::abs((m.points[c[6]][0] - m.points[c[0]][0]) * (m.points[c[6]][1] - m.points[c[0]][1]) * (m.points[c[6]][2] - m.points[c[0]][2]));
}

Point3 cell_centre(const IndexedMesh& m, std::uint32_t c) {
  Point3 s{0, 0, 0};
  for (std::uint32_t q : m.cell(c))
    for (std::size_t k = 0; k < 3; ++k) s[k] += m.points[q][k] / 8;
  return s;
}

}  // namespace surface_test

using namespace surface_test;

TEST_CASE("voxelize: a box surface gives exactly its grid of cubes, quads fanned into triangles") {
  TempDir dir("surface_box");
  const Surface s = read_surface(dir.write("box.off", box_off(2, 1, 1)));
  CHECK(s.points.size() == 8);
  CHECK(s.triangles.size() == 12);
  const IndexedMesh m = voxelize(s, 4, "box");
  CHECK(m.num_cells() == 4 * 2 * 2);
  CHECK(m.num_points() == 5 * 3 * 3);
  CHECK(cell_volume(m) == doctest::Approx(0.125));
  // rows of centres on the fan's diagonals (cells = 2: centres at 0.25/0.75, diagonals through them)
  CHECK(voxelize(read_surface(dir.write("cube.off", box_off(1, 1, 1))), 2, "cube").num_cells() == 8);
  CHECK(voxelize(read_surface(dir.write("cube1.off", box_off(1, 1, 1))), 1, "cube").num_cells() == 1);
}

TEST_CASE("voxelize: the octahedron's cells are exactly those whose centre is inside it") {
  const Surface s = octahedron();
  for (std::uint32_t cells : {7u, 20u, 41u}) {
    const IndexedMesh m = voxelize(s, cells, "octahedron");
    const double a = 2.0 / cells;
    std::size_t inside = 0;
    for (std::uint32_t c = 0; c < m.num_cells(); ++c) {
      const Point3 p = cell_centre(m, c);
      CHECK(std::abs(p[0]) + std::abs(p[1]) + std::abs(p[2]) <= 1 + 1e-12);
    }
    // every grid centre strictly inside is a cell (centres on the surface may go either way)
    for (std::uint32_t i = 0; i < cells; ++i)
      for (std::uint32_t j = 0; j < cells; ++j)
        for (std::uint32_t k = 0; k < cells; ++k) {
          const double x = -1 + (i + 0.5) * a, y = -1 + (j + 0.5) * a, z = -1 + (k + 0.5) * a;
          inside += std::abs(x) + std::abs(y) + std::abs(z) < 1 - 1e-12;
        }
    CHECK(m.num_cells() >= inside);
    CHECK(m.num_cells() * a * a * a == doctest::Approx(4.0 / 3).epsilon(cells < 10 ? 0.5 : 0.2));
  }
}

TEST_CASE("surface files: OBJ and STL (ASCII, binary) of the same box voxelize the same") {
  TempDir dir("surface_formats");
  std::string obj = "# a box\no box\n";
  for (const auto& p : box_corners(2, 1, 1)) obj += "v " + std::to_string(p[0]) + " " + std::to_string(p[1]) + " " + std::to_string(p[2]) + "\n";
  for (const auto& f : box_faces) obj += "f " + std::to_string(f[0] + 1) + "/1 " + std::to_string(f[1] + 1) + " " + std::to_string(f[2] + 1) + "//3 -" + std::to_string(8 - f[3]) + "\n";
  std::string ascii = "solid box\n", binary(80, ' ');
  const auto corners = box_corners(2, 1, 1);
  std::vector<std::array<int, 3>> tris;
  for (const auto& f : box_faces) tris.push_back({f[0], f[1], f[2]}), tris.push_back({f[0], f[2], f[3]});
  const std::uint32_t n = static_cast<std::uint32_t>(tris.size());
  binary.append(reinterpret_cast<const char*>(&n), 4);
  for (const auto& t : tris) {
    ascii += "facet normal 0 0 0\nouter loop\n";
    binary.append(12, '\0');
    for (int v : t) {
      ascii += "vertex " + std::to_string(corners[v][0]) + " " + std::to_string(corners[v][1]) + " " + std::to_string(corners[v][2]) + "\n";
      for (double x : corners[v]) {
        const float f = static_cast<float>(x);
        binary.append(reinterpret_cast<const char*>(&f), 4);
      }
    }
    binary.append(2, '\0');
    ascii += "endloop\nendfacet\n";
  }
  ascii += "endsolid box\n";
  for (const auto& file : {std::pair{"box.obj", obj}, std::pair{"box_ascii.stl", ascii}, std::pair{"box_binary.stl", binary}}) {
    const std::string name = file.first, text = file.second;  // not a structured binding: clang 14 cannot capture one
    CAPTURE(name);
    const Surface s = read_surface(dir.write(name, text));
    CHECK(s.points.size() == 8);
    CHECK(s.triangles.size() == 12);
    CHECK(voxelize(s, 4, name).num_cells() == 16);
  }
}

TEST_CASE("surface files and voxelization: bad input named") {
  TempDir dir("surface_bad");
  CHECK(message_of<FileError>([&] { (void)read_surface(dir.path() / "none.off"); }).find("no such file") != std::string::npos);
  CHECK(message_of<SemanticError>([&] { (void)read_surface(dir.write("idx.off", "OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 3\n")); })
            .find("face 0 uses vertex 3 of 3") != std::string::npos);
  CHECK(message_of<SemanticError>([&] { (void)read_surface(dir.write("nan.off", "OFF\n3 1 0\n0 0 0\nnan 0 0\n0 1 0\n3 0 1 2\n")); })
            .find("vertex 1 has a non-finite coordinate") != std::string::npos);
  CHECK(message_of<SemanticError>([&] { (void)read_surface(dir.write("two.off", "OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n2 0 1\n")); })
            .find("face 0 has 2 vertices") != std::string::npos);
  CHECK(message_of<SemanticError>([&] { (void)read_surface(dir.write("empty.obj", "v 0 0 0\n")); }).find("has no triangle") != std::string::npos);
  CHECK(message_of<SemanticError>([&] { (void)read_surface(dir.write("far.obj", "v 0 0 0\nf 1 2 3\n")); }).find("vertex 2 with 1 vertices") != std::string::npos);
  CHECK(message_of<ParseError>([&] { (void)read_surface(dir.write("short.stl", "abc")); }).find("84-byte") != std::string::npos);
  CHECK(message_of<UnsupportedError>([&] { (void)read_surface(dir.write("x.ply", "ply\n")); }).find("OFF, OBJ or STL") != std::string::npos);
  Surface open = octahedron();
  open.triangles.pop_back();
  CHECK(message_of<SemanticError>([&] { (void)voxelize(open, 8, "open"); }).find("not closed") != std::string::npos);
  // a slab 1 cm thick at 1 cell: the one cell is a 1 m cube whose centre, at z = 0.5 m, is outside
  CHECK(message_of<SemanticError>([&] { (void)voxelize(read_surface(dir.write("slab.off", box_off(1, 1, 0.01))), 1, "slab"); })
            .find("no cell centre lies inside") != std::string::npos);
  CHECK(message_of<SemanticError>([&] { (void)voxelize(octahedron(), 0, "zero"); }).find("at least 1 cell") != std::string::npos);
  CHECK(message_of<SemanticError>([&] { (void)voxelize(octahedron(), 100000, "huge"); }).find("more than 2^28") != std::string::npos);
}

}  // namespace test_surface
