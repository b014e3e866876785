// Surface files (OFF, OBJ, STL) and their voxelization: exact cell sets on shapes whose inside
// is known in closed form, every format giving the same cells, bad files refused by name.
#include <doctest/doctest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>
#include <limits>
#include <map>
#include <random>
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

// A subdivided octahedron (8 * 4^levels triangles) around the origin, oriented outward.
Surface subdivided_octahedron(int levels) {
  Surface s = octahedron();
  for (auto& t : s.triangles)
    if (s.points[t[0]][0] * s.points[t[1]][1] * s.points[t[2]][2] + s.points[t[0]][1] * s.points[t[1]][2] * s.points[t[2]][0] +
            s.points[t[0]][2] * s.points[t[1]][0] * s.points[t[2]][1] <
        0)
      std::swap(t[1], t[2]);
  for (int l = 0; l < levels; ++l) {
    std::map<std::pair<std::uint32_t, std::uint32_t>, std::uint32_t> mids;
    auto mid = [&](std::uint32_t a, std::uint32_t b) {
      const auto key = std::make_pair(std::min(a, b), std::max(a, b));
      if (const auto it = mids.find(key); it != mids.end()) return it->second;
      Point3 m{};
      for (std::size_t k = 0; k < 3; ++k) m[k] = (s.points[a][k] + s.points[b][k]) / 2;
      s.points.push_back(m);
      return mids[key] = static_cast<std::uint32_t>(s.points.size() - 1);
    };
    std::vector<std::array<std::uint32_t, 3>> finer;
    for (const auto& t : s.triangles) {
      const std::uint32_t a = mid(t[0], t[1]), b = mid(t[1], t[2]), c = mid(t[2], t[0]);
      finer.insert(finer.end(), {{t[0], a, c}, {t[1], b, a}, {t[2], c, b}, {a, b, c}});
    }
    s.triangles = std::move(finer);
  }
  return s;
}

// The winding number of a closed oriented surface around q (van Oosterom and Strackee's solid
// angle of each triangle): a whole number off the surface (0 outside; odd where a ray from q
// crosses it an odd number of times), in between only on it.
double winding_number(const Surface& s, const Point3& q) {
  double sum = 0;
  for (const auto& t : s.triangles) {
    std::array<Point3, 3> v{};
    std::array<double, 3> len{};
    for (std::size_t i = 0; i < 3; ++i) {
      for (std::size_t k = 0; k < 3; ++k) v[i][k] = s.points[t[i]][k] - q[k];
      len[i] = std::sqrt(v[i][0] * v[i][0] + v[i][1] * v[i][1] + v[i][2] * v[i][2]);
    }
    auto dot = [&](std::size_t i, std::size_t j) { return v[i][0] * v[j][0] + v[i][1] * v[j][1] + v[i][2] * v[j][2]; };
    const double det = v[0][0] * (v[1][1] * v[2][2] - v[1][2] * v[2][1]) - v[0][1] * (v[1][0] * v[2][2] - v[1][2] * v[2][0]) +
                       v[0][2] * (v[1][0] * v[2][1] - v[1][1] * v[2][0]);
    sum += 2 * std::atan2(det, len[0] * len[1] * len[2] + dot(0, 1) * len[2] + dot(0, 2) * len[1] + dot(1, 2) * len[0]);
  }
  return sum / (4 * std::acos(-1.0));
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

// Vertices in the plane y = z with equal lower bounds in y and z put the rays of rows j == k in
// the plane of many faces and on many edges. Edge signs computed in rounded arithmetic, which
// -march=native contracts into FMAs differently at each call, disagreed between the two
// triangles of an edge: odd crossings refused a closed surface (CGAL's mpi.off) or, with an
// even count, rows silently wrong. Exact signs: every row even, the cells those inside.
TEST_CASE("voxelize: rays in the plane of faces and along edges cross a closed surface an even number of times") {
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> radius(0.6, 1.4), shift(-0.003, 0.003);
  for (int shape = 0; shape < 6; ++shape) {
    Surface s = subdivided_octahedron(2);
    std::vector<bool> on_plane;
    for (Point3& p : s.points) {
      const double r = 7 * radius(rng);
      for (double& x : p) x *= r;
      if (std::abs(p[1] - p[2]) < 2) p[2] = p[1];  // onto the plane y = z
      p[0] += shift(rng);
      on_plane.push_back(p[1] == p[2]);
    }
    // the same lower bound in y and z: row j of y and row j of z have the same centre
    double ylo = INFINITY, zlo = INFINITY;
    for (const Point3& p : s.points) ylo = std::min(ylo, p[1]), zlo = std::min(zlo, p[2]);
    for (std::size_t i = 0; i < s.points.size(); ++i) s.points[i][2] = on_plane[i] ? s.points[i][1] : s.points[i][2] + (ylo - zlo);
    for (std::uint32_t cells : {5u, 6u, 7u, 9u}) {
      CAPTURE(shape);
      CAPTURE(cells);
      IndexedMesh m;
      REQUIRE_NOTHROW(m = voxelize(s, cells, "star"));
      Point3 lo{INFINITY, INFINITY, INFINITY}, hi{-INFINITY, -INFINITY, -INFINITY};
      for (const Point3& p : s.points)
        for (std::size_t k = 0; k < 3; ++k) lo[k] = std::min(lo[k], p[k]), hi[k] = std::max(hi[k], p[k]);
      const double a = std::max({hi[0] - lo[0], hi[1] - lo[1], hi[2] - lo[2]}) / cells;
      // inside: an odd winding number just off q the way the voxelizer's rays are (y + eps,
      // z + eps^2: many centres lie on faces, some where two sheets meet and cancel); on the
      // surface (a winding number not whole): either way
      auto inside_by_winding = [&](const Point3& q) {
        const double eps = 1e-6 * a;
        const double w = winding_number(s, {q[0], q[1] + eps, q[2] + eps * eps}), whole = std::round(w);
        return std::abs(w - whole) > 0.1 ? -1 : static_cast<int>(std::abs(whole)) % 2;
      };
      std::size_t outside_cells = 0, inside_cells = 0;
      for (std::uint32_t c = 0; c < m.num_cells(); ++c) {
        const int in = inside_by_winding(cell_centre(m, c));
        outside_cells += in == 0;
        inside_cells += in == 1;
      }
      CHECK(outside_cells == 0);
      // every grid centre inside is a cell
      std::size_t inside = 0;
      auto centre = [&](std::size_t k, int i) { return lo[k] + (i + 0.5) * a; };
      for (int i = 0; centre(0, i) < hi[0]; ++i)
        for (int j = 0; centre(1, j) < hi[1]; ++j)
          for (int k = 0; centre(2, k) < hi[2]; ++k) {
            inside += inside_by_winding({centre(0, i), centre(1, j), centre(2, k)}) == 1;
          }
      CHECK(inside_cells == inside);
    }
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

// OFF variants of other tools (CGAL's data: COFF with vertex colours, NOFF with normals), an
// ASCII STL of several solids, and a binary STL whose 80-byte comment starts "solid" and says
// "facet", and files with zero-area facets (a corner repeated): all the same tetrahedron.
// Before, COFF and NOFF were refused, every solid after the first dropped without a word, the
// binary file misread as ASCII, and a repeated corner made the surface "not closed".
TEST_CASE("surface files: OFF variants, STL of several solids, binary STL that starts with solid") {
  TempDir dir("surface_variants");
  const std::string faces = "3 0 2 1\n3 0 1 3\n3 0 3 2\n3 1 2 3\n";
  const std::vector<std::string> corners{"0 0 0", "1 0 0", "0 1 0", "0 0 1"};
  auto off = [&](const std::string& header, const std::string& extra) {
    std::string t = header + "\n4 4 0\n";
    for (const auto& c : corners) t += c + extra + "\n";
    return t + faces;
  };
  std::string multi;
  const std::array<std::array<int, 3>, 4> tris{{{0, 2, 1}, {0, 1, 3}, {0, 3, 2}, {1, 2, 3}}};
  for (std::size_t f = 0; f < tris.size(); ++f) {
    multi += "solid part" + std::to_string(f) + "\nfacet normal 0 0 0\nouter loop\n";
    for (int v : tris[f]) multi += "vertex " + corners[static_cast<std::size_t>(v)] + "\n";
    multi += "endloop\nendfacet\nendsolid part" + std::to_string(f) + "\n";
  }
  std::string binary = "solid exported by a CAD tool, facet normals included";
  binary.resize(80, ' ');
  const std::uint32_t n = 4;
  binary.append(reinterpret_cast<const char*>(&n), 4);
  for (const auto& t : tris) {
    binary.append(12, '\0');
    for (int v : t)
      for (int k = 0; k < 3; ++k) {
        const float x = k == v - 1 ? 1.0f : 0.0f;  // corner v: the unit vector e_{v-1}, or 0
        binary.append(reinterpret_cast<const char*>(&x), 4);
      }
    binary.append(2, '\0');
  }
  // facets with a repeated corner (zero area, common in STL exports) bound nothing
  std::string degenerate_off = off("OFF", "");
  degenerate_off.replace(degenerate_off.find("4 4 0"), 5, "4 6 0");
  degenerate_off += "3 0 0 1\n4 2 2 3 3\n";
  std::string degenerate_stl = multi;
  degenerate_stl.insert(degenerate_stl.find("endsolid part0"), "facet normal 0 0 0\nouter loop\nvertex 0 0 0\nvertex 0 0 0\nvertex 1 0 0\nendloop\nendfacet\n");
  const std::vector<std::pair<std::string, std::string>> files{
      {"degenerate.off", degenerate_off}, {"degenerate.stl", degenerate_stl},
      {"plain.off", off("OFF", "")},          {"colour.off", off("COFF", " 255 0 0 255")}, {"normal.off", off("NOFF", " 0 0 1")},
      {"both.off", off("CNOFF", " 1 0 0 0 0 1")}, {"texture.off", off("STOFF", " 0.5 0.5")}, {"solids.stl", multi},
      {"binary.stl", binary}};
  for (const auto& file : files) {
    const std::string name = file.first;
    CAPTURE(name);
    const Surface s = read_surface(dir.write(name, file.second));
    CHECK(s.points.size() == 4);
    CHECK(s.triangles.size() == 4);
    CHECK(voxelize(s, 4, name).num_cells() == 10);  // centres (i + 1/2)/4 with i + j + k <= 2
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
  // counts that do not match the data: a vertex line with a 4th number, a face past the count
  CHECK(message_of<ParseError>([&] { (void)read_surface(dir.write("v4.off", "OFF\n3 1 0\n0 0 0 1\n1 0 0\n0 1 0\n3 0 1 2\n")); })
            .find("v4.off:3: expected the end of the line after vertex 0's x y z") != std::string::npos);
  CHECK(message_of<ParseError>([&] { (void)read_surface(dir.write("f2.off", "OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n3 0 2 1\n")); })
            .find("f2.off:7: expected the end of the file after the 1 faces the header declares") != std::string::npos);
  CHECK(message_of<UnsupportedError>([&] { (void)read_surface(dir.write("h.off", "4OFF\n1 1 0\n0 0 0 1\n")); }).find("4OFF files") !=
        std::string::npos);
  CHECK(message_of<UnsupportedError>([&] { (void)read_surface(dir.write("b.off", "OFF BINARY\n")); }).find("binary OFF") != std::string::npos);
  CHECK(message_of<ParseError>([&] { (void)read_surface(dir.write("x.off", "XOFF\n")); }).find("found 'XOFF'") != std::string::npos);
  Surface open = octahedron();
  open.triangles.pop_back();
  CHECK(message_of<SemanticError>([&] { (void)voxelize(open, 8, "open"); }).find("not closed") != std::string::npos);
  // a slab 1 cm thick at 1 cell: the one cell is a 1 m cube whose centre, at z = 0.5 m, is outside
  CHECK(message_of<SemanticError>([&] { (void)voxelize(read_surface(dir.write("slab.off", box_off(1, 1, 0.01))), 1, "slab"); })
            .find("no cell centre lies inside") != std::string::npos);
  CHECK(message_of<SemanticError>([&] { (void)voxelize(octahedron(), 0, "zero"); }).find("at least 1 cell") != std::string::npos);
  CHECK(message_of<SemanticError>([&] { (void)voxelize(octahedron(), 100000, "huge"); }).find("more than the 2^22") != std::string::npos);
}

// A tetrahedron with corners at the origin and at s along each axis.
Surface corner_tetrahedron(double sx, double sy, double sz) {
  Surface t;
  t.points = {{0, 0, 0}, {sx, 0, 0}, {0, sy, 0}, {0, 0, sz}};
  t.triangles = {{0, 2, 1}, {0, 1, 3}, {0, 3, 2}, {1, 2, 3}};
  return t;
}

TEST_CASE("voxelize: the cells do not depend on the surface's scale, 1e-200 to 1e200") {
  // At 1e200 the edge functions' products overflowed to inf and the crossings were NaN, cast to
  // int (UB; found by fuzz_voxelize under UBSan): the voxelizer now works in grid units.
  const IndexedMesh unit = voxelize(corner_tetrahedron(1, 1, 1), 6, "unit");
  for (const double scale : {1e-200, 1e-100, 1e100, 1e200, 1e300}) {
    CAPTURE(scale);
    const IndexedMesh m = voxelize(corner_tetrahedron(scale, scale, scale), 6, "scaled");
    REQUIRE(m.num_cells() == unit.num_cells());
    for (std::uint32_t c = 0; c < m.num_cells(); ++c)
      for (std::size_t k = 0; k < 3; ++k) CHECK(cell_centre(m, c)[k] / scale == doctest::Approx(cell_centre(unit, c)[k]));
  }
}

TEST_CASE("voxelize: grids that would take gigabytes and extents that overflow are refused by name") {
  // A sheet 1e-5 thick across x at 16384 cells: a grid of 1 x 16384 x 16384 = 2^28 cells passed
  // the old bound and allocated a list of crossings per row, 6 GB before the first triangle.
  CHECK(message_of<SemanticError>([&] { (void)voxelize(corner_tetrahedron(1e-5, 1, 1), 16384, "sheet"); })
            .find("sheet: voxelizing at 16384 cells makes a grid of 2.68435e+08 cells, more than the 2^22") != std::string::npos);
  // cells near 2^32: the cells along x overflowed an int (UB) before the grid was bounded
  CHECK(message_of<SemanticError>([&] { (void)voxelize(octahedron(), 4000000000u, "max"); }).find("max: cells of side 5e-10 are too small") !=
        std::string::npos);
  CHECK(message_of<SemanticError>([&] { (void)voxelize(octahedron(), 1000000000u, "1e9"); }).find("more than the 2^22") != std::string::npos);
  // from -1e308 to 1e308 the extent is inf (the cells along x were NaN cast to int)
  Surface wide = corner_tetrahedron(1e308, 1, 1);
  wide.points[0][0] = -1e308;
  CHECK(message_of<SemanticError>([&] { (void)voxelize(wide, 4, "wide"); }).find("wide: the surface's extent, inf, cannot be cut into 4 cells") !=
        std::string::npos);
  // 1e-5 across at 1e10 from the origin at 24 cells: corners 1e10 + i 4.2e-7 round together
  // (the rounding unit there is 1.9e-6), and the hexahedra had zero volume, silently
  auto moved = [](double by) {
    Surface t = corner_tetrahedron(1e-5, 1e-5, 1e-5);
    for (Point3& p : t.points) p = {p[0] + by, p[1] + by, p[2] + by};
    return t;
  };
  CHECK(message_of<SemanticError>([&] { (void)voxelize(moved(1e10), 24, "far"); }).find("too small for a surface 1e+10 from the origin") !=
        std::string::npos);
  CHECK(voxelize(moved(1), 24, "near").num_cells() > 0);  // at 1 from the origin a cell is 1.9e9 rounding units
  // the smallest subnormal extent halves to a cube of side 0 (its cells along x were inf cast to int)
  const double tiny = std::numeric_limits<double>::denorm_min();
  CHECK(message_of<SemanticError>([&] { (void)voxelize(corner_tetrahedron(tiny, tiny, tiny), 2, "tiny"); })
            .find("tiny: the surface's extent, 4.94066e-324, cannot be cut into 2 cells") != std::string::npos);
}

}  // namespace test_surface
