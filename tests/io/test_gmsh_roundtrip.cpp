// Checks the meshes gmsh_roundtrip.cmake made with the real gmsh (folder in SEWN_GMSH_OUT).
// Expected counts come from the construction in each .geo; for the unstructured box they come
// from gmsh's own log and from comparing the formats with each other.
#include <doctest/doctest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdlib>
#include <map>
#include <sstream>

#include "io_test_util.hpp"
#include "sewn/io/cleanup.hpp"
#include "sewn/io/geometry.hpp"
#include "sewn/io/read.hpp"

namespace test_gmsh_roundtrip {

using namespace sewn;
using namespace sewn::io;

namespace {

std::filesystem::path out_dir() {
  const char* d = std::getenv("SEWN_GMSH_OUT");
  REQUIRE_MESSAGE(d != nullptr, "SEWN_GMSH_OUT is not set: run this through the io_gmsh_roundtrip CTest");
  return d;
}

MeshFile load(const std::string& geo, const std::string& fmt) {
  const std::string ext = fmt == "mesh" || fmt == "vtk" ? fmt : "msh";
  const auto p = out_dir() / (geo + "." + fmt + "." + ext);
  INFO("reading " << p.string());
  return read_mesh_file(p);
}

// gmsh's closing summary, "Info    : 339 nodes 1745 elements" (what it meshed, before any
// physical-group filtering on save).
std::pair<std::size_t, std::size_t> gmsh_reported(const std::string& geo) {
  std::istringstream log(test::read_text(out_dir() / (geo + ".msh41.log")));
  std::pair<std::size_t, std::size_t> last{0, 0};
  for (std::string line; std::getline(log, line);) {
    if (line.rfind("Info", 0) != 0) continue;
    std::istringstream words(line.substr(line.find(':') + 1));
    std::size_t n = 0, m = 0;
    std::string w1, w2, rest;
    if ((words >> n >> w1 >> m >> w2) && w1 == "nodes" && w2 == "elements" && !(words >> rest)) last = {n, m};
  }
  REQUIRE_MESSAGE(last.first > 0, "no 'N nodes M elements' line in gmsh's log");
  return last;
}

std::size_t count(const IndexedMesh& m, CellType t) {
  return static_cast<std::size_t>(std::count(m.types.begin(), m.types.end(), t));
}

double total_measure(const IndexedMesh& m, int dim) {
  double s = 0;
  for (std::uint32_t c = 0; c < m.num_cells(); ++c)
    if (cell_dimension(m.types[c]) == dim) s += cell_measure(m, c);
  return s;
}

// Cells as sorted lists of coordinates: equal across files even when node numbering differs.
std::vector<std::pair<CellType, std::vector<Point3>>> canonical(const IndexedMesh& m) {
  std::vector<std::pair<CellType, std::vector<Point3>>> r;
  for (std::uint32_t c = 0; c < m.num_cells(); ++c) {
    std::vector<Point3> pts;
    for (std::uint32_t v : m.cell(c)) pts.push_back(m.points[v]);
    std::sort(pts.begin(), pts.end());
    r.emplace_back(m.types[c], std::move(pts));
  }
  std::sort(r.begin(), r.end());
  return r;
}

struct Expect {
  CellType type;
  std::size_t cells;
  std::size_t points;
  double measure;
  std::int32_t tag;
};

}  // namespace

TEST_CASE("structured meshes: counts from the .geo construction, in MSH 2.2, MSH 4.1 and VTK") {
  const std::map<std::string, Expect> expect{{"box_hex", {CellType::hexahedron, 27, 64, 6.0, 5}},
                                             {"square_tri", {CellType::triangle, 18, 16, 1.0, 3}},
                                             {"square_quad", {CellType::quad, 9, 16, 1.0, 3}},
                                             {"slab_prism", {CellType::prism, 36, 48, 0.5, 9}}};
  for (const auto& entry : expect) {
    const std::string& geo = entry.first;  // CAPTURE and lambdas cannot take bindings (clang 14)
    const Expect& e = entry.second;
    const auto m22 = load(geo, "msh22");
    const auto m41 = load(geo, "msh41");
    for (const auto* f : {&m22, &m41}) {
      CAPTURE(geo);
      CAPTURE(f->version);
      CHECK(f->mesh.num_points() == e.points);
      CHECK(f->mesh.num_cells() == e.cells);  // only the physical group is saved
      CHECK(count(f->mesh, e.type) == e.cells);
      CHECK(total_measure(f->mesh, cell_dimension(e.type)) == doctest::Approx(e.measure).epsilon(1e-12));
      CHECK(std::all_of(f->mesh.tags.begin(), f->mesh.tags.end(), [&](std::int32_t t) { return t == e.tag; }));
      REQUIRE(f->tag_names.size() == 1);
      CHECK(f->tag_names[0].tag == e.tag);
      // real Gmsh prisms and hexahedra, converted, are positive in VTK's convention
      CHECK_NOTHROW(check_mesh_geometry(f->mesh, geo));
    }
    CHECK(canonical(m22.mesh) == canonical(m41.mesh));
    const auto vtk = load(geo, "vtk");
    CAPTURE(geo);
    CHECK(count(vtk.mesh, e.type) == e.cells);
    CHECK(canonical(vtk.mesh) == canonical(m41.mesh));
    CHECK_NOTHROW(check_mesh_geometry(vtk.mesh, geo + ".vtk"));
  }
}

TEST_CASE("binary MSH 2.2 and 4.1 (gmsh -bin) read as the ASCII files of the same mesh") {
  for (const std::string geo : {"box_hex", "square_tri", "square_quad", "slab_prism", "box_tet"}) {
    for (const std::string version : {"msh22", "msh41"}) {
      CAPTURE(geo);
      CAPTURE(version);
      const auto text = load(geo, version), binary = load(geo, version + "b");
      CHECK(binary.version == text.version);
      CHECK(binary.mesh.types == text.mesh.types);
      CHECK(binary.mesh.conn == text.mesh.conn);
      CHECK(binary.mesh.tags == text.mesh.tags);
      CHECK(binary.tag_names.size() == text.tag_names.size());
      REQUIRE(binary.mesh.num_points() == text.mesh.num_points());
      // the ASCII file prints 16 significant digits, the binary one holds the doubles
      for (std::size_t p = 0; p < text.mesh.points.size(); ++p)
        for (std::size_t k = 0; k < 3; ++k)
          CHECK(std::abs(binary.mesh.points[p][k] - text.mesh.points[p][k]) <= 1e-15 * std::max(1.0, std::abs(text.mesh.points[p][k])));
    }
  }
}

TEST_CASE("structured meshes through Gmsh's MEDIT export") {
  const auto hex = load("box_hex", "mesh");
  CHECK(hex.mesh.num_points() == 64);
  CHECK(count(hex.mesh, CellType::hexahedron) == 27);
  CHECK(total_measure(hex.mesh, 3) == doctest::Approx(6.0).epsilon(1e-12));
  CHECK_NOTHROW(check_mesh_geometry(hex.mesh, "box_hex.mesh"));
  // Gmsh's MEDIT writer leaves prisms out: only the vertices arrive
  const auto slab = load("slab_prism", "mesh");
  CHECK(slab.mesh.num_points() == 48);
  CHECK(slab.mesh.num_cells() == 0);
  CHECK(count(load("square_quad", "mesh").mesh, CellType::quad) == 9);
  CHECK(count(load("square_tri", "mesh").mesh, CellType::triangle) == 18);
}

TEST_CASE("unstructured tetrahedra: formats agree with each other and with gmsh's own count") {
  const auto [nodes, elements] = gmsh_reported("box_tet");
  const auto m22 = load("box_tet", "msh22");
  const auto m41 = load("box_tet", "msh41");
  MESSAGE("gmsh reports " << nodes << " nodes and " << elements << " elements; " << count(m41.mesh, CellType::tetrahedron)
                          << " tetrahedra read");
  for (const auto* f : {&m22, &m41}) {
    CAPTURE(f->version);
    // no physical groups: every element is saved, points (type 15) included
    CHECK(f->mesh.num_points() == nodes);
    CHECK(f->mesh.num_cells() + f->skipped_points == elements);
    CHECK(f->file_elements == elements);
    CHECK(f->skipped_points == 8);  // the box's corners
    CHECK(count(f->mesh, CellType::segment) > 0);
    CHECK(count(f->mesh, CellType::triangle) > 0);
    CHECK(total_measure(f->mesh, 3) == doctest::Approx(1.0).epsilon(1e-12));
    CHECK(total_measure(f->mesh, 2) == doctest::Approx(6.0).epsilon(1e-12));  // the boundary triangles
    CHECK_NOTHROW(check_mesh_geometry(f->mesh, "box_tet"));
  }
  CHECK(count(m22.mesh, CellType::tetrahedron) > 100);
  // every triangle Gmsh saved is a boundary face of a tetrahedron, every line an edge
  IndexedMesh solid = m41.mesh;
  CHECK(drop_embedded_cells(solid) == count(m41.mesh, CellType::triangle) + count(m41.mesh, CellType::segment));
  CHECK(solid.num_cells() == count(m41.mesh, CellType::tetrahedron));
  CHECK(canonical(m22.mesh) == canonical(m41.mesh));
  const auto vtk = load("box_tet", "vtk");
  CHECK(vtk.file_elements == elements);
  CHECK(canonical(vtk.mesh) == canonical(m41.mesh));
  const auto medit = load("box_tet", "mesh");
  CHECK(count(medit.mesh, CellType::tetrahedron) == count(m41.mesh, CellType::tetrahedron));
  CHECK(medit.mesh.num_points() == nodes);
  CHECK_NOTHROW(check_mesh_geometry(medit.mesh, "box_tet.mesh"));
}

}  // namespace test_gmsh_roundtrip
