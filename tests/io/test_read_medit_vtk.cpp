#include <doctest/doctest.h>

#include <cmath>
#include <cstring>
#include <random>

#include "io_test_util.hpp"
#include "sewn/io/geometry.hpp"
#include "sewn/io/read.hpp"

namespace test_read_medit_vtk {

using namespace sewn;
using namespace sewn::io;
using sewn::io::test::message_of;

namespace {

std::vector<std::uint32_t> cell_of(const IndexedMesh& m, std::uint32_t c) {
  const auto v = m.cell(c);
  return {v.begin(), v.end()};
}

const std::string medit_head = "MeshVersionFormatted 2\nDimension 3\nVertices\n4\n0 0 0 1\n1 0 0 1\n0 1 0 1\n0 0 1 1\n";

MeshFile medit(const std::string& text) { return parse_medit(text, "bad.mesh"); }
MeshFile vtk(const std::string& text) { return parse_vtk(text, "bad.vtk"); }

const std::string vtk_head = "# vtk DataFile Version 4.2\ntitle\nASCII\nDATASET UNSTRUCTURED_GRID\n";
const std::string vtk_points = "POINTS 4 double\n0 0 0 1 0 0 0 1 0 0 0 1\n";

}  // namespace

TEST_CASE("medit: vertices, edges, quadrilaterals and a hexahedron with references") {
  const MeshFile f = read_medit(test::data("cube.mesh"));
  CHECK(f.version == "2");
  CHECK(f.mesh.num_points() == 8);
  REQUIRE(f.mesh.num_cells() == 5);
  CHECK(f.mesh.types ==
        std::vector<CellType>{CellType::segment, CellType::segment, CellType::quad, CellType::quad, CellType::hexahedron});
  CHECK(f.mesh.tags == std::vector<std::int32_t>{11, 11, 21, 22, 3});
  CHECK(cell_of(f.mesh, 4) == std::vector<std::uint32_t>{0, 1, 2, 3, 4, 5, 6, 7});
  CHECK_NOTHROW(check_mesh_geometry(f.mesh, "cube.mesh"));
}

TEST_CASE("medit numbers its vertices from 1, legacy VTK its points from 0") {
  const MeshFile m = medit("MeshVersionFormatted 1\nDimension 2\nVertices 3\n0 0 0\n1 0 0\n0 2 0\nTriangles 1\n1 2 3 4\nEnd\n");
  CHECK(m.point_numbers() == std::vector<std::int64_t>{1, 2, 3});
  CHECK(m.element_tags.empty());
  const MeshFile v = vtk(vtk_head + vtk_points + "CELLS 1 5\n4 0 1 2 3\nCELL_TYPES 1\n10\n");
  CHECK(v.point_numbers() == std::vector<std::int64_t>{0, 1, 2, 3});
}

TEST_CASE("medit: 2D files get z = 0") {
  const MeshFile f = medit("MeshVersionFormatted 1\nDimension 2\nVertices 3\n0 0 0\n1 0 0\n0 2 0\nTriangles 1\n1 2 3 4\nEnd\n");
  REQUIRE(f.mesh.num_cells() == 1);
  CHECK(f.mesh.points[2] == Point3{0, 2, 0});
  CHECK(f.mesh.tags[0] == 4);
}

TEST_CASE("medit bad input") {
  CHECK(message_of<ParseError>([] { medit(""); }).find("bad.mesh:1: expected 'MeshVersionFormatted'") == 0);
  CHECK(message_of<SemanticError>([] { medit(medit_head + "Tetrahedra\n1\n1 2 3 9 0\nEnd\n"); })
            .find("bad.mesh:11: Tetrahedra entry 1 refers to vertex 9 but the vertices are numbered 1..4") == 0);
  message_of<SemanticError>([] { medit(medit_head + "Tetrahedra\n1\n0 1 2 3 0\nEnd\n"); });
  message_of<SemanticError>([] { medit(medit_head + "Tetrahedra\n1\n1 2 2 3 0\nEnd\n"); });
  CHECK(message_of<ParseError>([] { medit(medit_head + "Tetrahedra\n1\n1 2 3 4 0\n"); }).find("truncated") !=
        std::string::npos);
  message_of<ParseError>([] { medit(medit_head + "Tetrahedra\n2\n1 2 3 4 0\n"); });
  message_of<ParseError>([] { medit(medit_head + "Tetrahedra\n-2\nEnd\n"); });
  message_of<ParseError>([] { medit(medit_head + "Tetrahedra\n1\n1 2 x 4 0\nEnd\n"); });
  message_of<SemanticError>([] { medit("MeshVersionFormatted 2\nDimension 4\n"); });
  message_of<UnsupportedError>([] { medit("MeshVersionFormatted 7\n"); });
  message_of<UnsupportedError>([] { medit(medit_head + "Prisms\n0\nEnd\n"); });
  message_of<UnsupportedError>([] { medit(medit_head + "SolAtVertices\n0\nEnd\n"); });
  message_of<ParseError>([] { medit("MeshVersionFormatted 2\nDimension 3\nTriangles\n0\nEnd\n"); });
  CHECK(message_of<SemanticError>([] { medit("MeshVersionFormatted 2\nDimension 3\nVertices\n1\n0 nan 0 1\nEnd\n"); })
            .find("bad.mesh:5: vertex 1 has a non-finite y coordinate") == 0);
  message_of<SemanticError>([] { medit("MeshVersionFormatted 2\nDimension 3\nVertices\n1\n0 0 1e400 1\nEnd\n"); });
  message_of<ParseError>([] { medit("MeshVersionFormatted 2\nDimension 3\nVertices\n3000000000\n0 0 0 1\n"); });
}

TEST_CASE("legacy vtk: files written by VTK itself, ASCII and binary, 4.2 and 5.1, read alike") {
  const std::vector<std::uint32_t> hex{0, 1, 2, 3, 4, 5, 6, 7};
  const std::vector<std::uint32_t> wedge{4, 7, 5, 8, 10, 9};
  for (const std::string name : {"sample42_ascii.vtk", "sample51_ascii.vtk", "sample42_binary.vtk", "sample51_binary.vtk"}) {
    CAPTURE(name);
    const MeshFile f = read_vtk(test::data(name));
    CHECK(f.mesh.num_points() == 14);
    CHECK(f.mesh.points[11] == Point3{0.5, 0.5, -1});
    REQUIRE(f.mesh.num_cells() == 7);
    CHECK(f.skipped_points == 1);
    CHECK(f.file_elements == 8);
    CHECK(f.mesh.types == std::vector<CellType>{CellType::hexahedron, CellType::prism, CellType::pyramid,
                                                CellType::tetrahedron, CellType::quad, CellType::triangle,
                                                CellType::segment});
    CHECK(cell_of(f.mesh, 0) == hex);
    CHECK(cell_of(f.mesh, 1) == wedge);
    CHECK(f.mesh.tags == std::vector<std::int32_t>{7, 8, 9, 10, 11, 12, 13});  // the integer "material" array
    CHECK_NOTHROW(check_mesh_geometry(f.mesh, name));
  }
}

TEST_CASE("legacy vtk: the tag array can be chosen by name; pixels and voxels become quads and hexahedra") {
  const std::string text = vtk_head + vtk_points +
                           "CELLS 2 10\n4 0 1 2 3\n4 0 1 2 3\nCELL_TYPES 2\n8\n10\n"
                           "CELL_DATA 2\nSCALARS first int 1\nLOOKUP_TABLE default\n1 2\n"
                           "SCALARS region float\nLOOKUP_TABLE default\n5 6\n";
  CHECK(vtk(text).mesh.tags == std::vector<std::int32_t>{1, 2});
  ReadOptions opt;
  opt.vtk_tag_array = "region";
  const MeshFile f = parse_vtk(text, "t.vtk", opt);
  CHECK(f.mesh.tags == std::vector<std::int32_t>{5, 6});
  CHECK(f.mesh.types[0] == CellType::quad);
  CHECK(cell_of(f.mesh, 0) == std::vector<std::uint32_t>{0, 1, 3, 2});
  opt.vtk_tag_array = "missing";
  message_of<SemanticError>([&] { parse_vtk(text, "t.vtk", opt); });
}

TEST_CASE("legacy vtk bad input") {
  const std::string cells = "CELLS 1 5\n4 0 1 2 3\nCELL_TYPES 1\n10\n";
  CHECK_NOTHROW(vtk(vtk_head + vtk_points + cells));
  message_of<ParseError>([] { vtk(""); });
  message_of<ParseError>([] { vtk("# not vtk\n"); });
  message_of<UnsupportedError>([] { vtk("# vtk DataFile Version 6.0\nt\nASCII\nDATASET UNSTRUCTURED_GRID\n"); });
  message_of<UnsupportedError>([] { vtk("# vtk DataFile Version 3.0\nt\nASCII\nDATASET POLYDATA\n"); });
  message_of<ParseError>([] { vtk("# vtk DataFile Version 3.0\nt\nEBCDIC\nDATASET UNSTRUCTURED_GRID\n"); });
  CHECK(message_of<SemanticError>([&] { vtk(vtk_head + vtk_points + "CELLS 1 5\n4 0 1 2 9\nCELL_TYPES 1\n10\n"); })
            .find("bad.vtk:7: cell 0 refers to point 9 but there are 4 points") == 0);
  message_of<SemanticError>([&] { vtk(vtk_head + vtk_points + "CELLS 1 5\n4 0 1 2 3\nCELL_TYPES 1\n250\n"); });
  message_of<UnsupportedError>([&] { vtk(vtk_head + vtk_points + "CELLS 1 5\n4 0 1 2 3\nCELL_TYPES 1\n24\n"); });
  message_of<SemanticError>([&] { vtk(vtk_head + vtk_points + "CELLS 1 5\n4 0 1 2 3\nCELL_TYPES 1\n12\n"); });
  message_of<SemanticError>([&] { vtk(vtk_head + vtk_points + "CELLS 1 5\n4 0 1 2 3\nCELL_TYPES 2\n10 10\n"); });
  message_of<SemanticError>([&] { vtk(vtk_head + vtk_points + "CELLS 2 5\n4 0 1 2 3\nCELL_TYPES 2\n10 10\n"); });
  message_of<SemanticError>([&] { vtk(vtk_head + vtk_points + "CELLS 1 6\n4 0 1 2 3 3\nCELL_TYPES 1\n10\n"); });
  message_of<SemanticError>([&] { vtk(vtk_head + vtk_points + cells + "CELL_DATA 3\n"); });
  message_of<ParseError>([&] { vtk(vtk_head + vtk_points + "CELLS -1 5\n"); });
  message_of<ParseError>([&] { vtk(vtk_head + vtk_points + "CELLS 1 5\n4 0 1 two 3\n"); });
  message_of<ParseError>([&] { vtk(vtk_head + "POINTS 4 double\n0 0 0 1 0 0\n"); });
  message_of<ParseError>([&] { vtk(vtk_head + "POINTS 4 quaternion\n"); });
  message_of<ParseError>([&] { vtk(vtk_head + vtk_points + "CELLS 1 5\n4 0 1 2 3\n"); });
  CHECK(message_of<SemanticError>([&] { vtk(vtk_head + "POINTS 1 float\n0 nan 0\n"); }).find("point 0 has a non-finite") !=
        std::string::npos);
  message_of<SemanticError>([&] { vtk(vtk_head + "POINTS 1 float\n0 0 -inf\n"); });
  // 5.1 offsets that run backwards or past the connectivity
  const std::string h5 = "# vtk DataFile Version 5.1\nt\nASCII\nDATASET UNSTRUCTURED_GRID\n" + vtk_points;
  CHECK_NOTHROW(vtk(h5 + "CELLS 2 4\nOFFSETS vtktypeint64\n0 4\nCONNECTIVITY vtktypeint64\n0 1 2 3\nCELL_TYPES 1\n10\n"));
  message_of<SemanticError>([&] { vtk(h5 + "CELLS 2 4\nOFFSETS vtktypeint64\n0 9\nCONNECTIVITY vtktypeint64\n0 1 2 3\n"); });
  message_of<SemanticError>([&] { vtk(h5 + "CELLS 2 4\nOFFSETS vtktypeint64\n1 4\nCONNECTIVITY vtktypeint64\n0 1 2 3\n"); });
  message_of<SemanticError>(
      [&] { vtk(h5 + "CELLS 3 4\nOFFSETS vtktypeint64\n0 4 2\nCONNECTIVITY vtktypeint64\n0 1 2 3\n"); });
  message_of<ParseError>([&] { vtk(h5 + "CELLS 2 4\nOFFSETS double\n0 4\n"); });
  // string arrays cut short: ASCII lines missing, a BINARY length past the end
  CHECK(message_of<ParseError>([&] { vtk(vtk_head + "FIELD f 1\nnote 1 3 string\na\nb\n"); }).find("string 2 of 3 of note") !=
        std::string::npos);
  const std::string bin_head = "# vtk DataFile Version 4.2\ntitle\nBINARY\nDATASET UNSTRUCTURED_GRID\n";
  CHECK(message_of<SemanticError>([&] { vtk(bin_head + "FIELD f 1\nnote 1 1 string\n\xc9" + "abc\n"); }).find("9 bytes long") !=
        std::string::npos);
}

TEST_CASE("legacy vtk binary: truncated data and huge declared counts fail before allocating") {
  const std::string head = "# vtk DataFile Version 4.2\nt\nBINARY\nDATASET UNSTRUCTURED_GRID\n";
  const auto m = message_of<ParseError>([&] { vtk(head + "POINTS 1000000000 double\n\x3f\xf0"); });
  CHECK(m.find("bad.vtk: expected POINTS: 3000000000 binary values of 8 bytes") == 0);
  message_of<SemanticError>([&] { vtk(head + "POINTS 100000000000000000 double\n"); });
  std::string pts = head + "POINTS 1 float\n";
  pts += std::string("\x3f\x80\x00\x00\x00\x00\x00\x00\x00\x00", 10);  // 1.0, 0, then 2 bytes of z
  message_of<ParseError>([&] { vtk(pts); });
  std::string nanpt = head + "POINTS 1 float\n";
  nanpt += std::string("\x7f\xc0\x00\x00\x00\x00\x00\x00\x00\x00\x00\x00", 12);
  message_of<SemanticError>([&] { vtk(nanpt); });
}

namespace {

// Parses every prefix of a sample; returns the prefix lengths that parse without error.
template <class Parse>
std::vector<std::size_t> accepted_prefixes(const std::string& text, Parse parse) {
  std::vector<std::size_t> ok;
  for (std::size_t n = 0; n < text.size(); ++n) {
    try {
      parse(text.substr(0, n));
      ok.push_back(n);
    } catch (const IoError&) {
    }
  }
  return ok;
}

}  // namespace

TEST_CASE("truncation anywhere in a Gmsh or MEDIT file is an error") {
  // both formats mark their end ($EndElements, End), so only prefixes that contain the whole
  // final keyword may parse
  for (const std::string name : {"two_tets.msh", "mixed41.msh"}) {
    const std::string text = test::read_text(test::data(name));
    const std::size_t complete = text.rfind("$EndElements") + std::strlen("$EndElements");
    for (std::size_t n : accepted_prefixes(text, [&](const std::string& t) { return parse_gmsh(t, name); })) {
      CAPTURE(name);
      CAPTURE(n);
      CHECK(n >= complete);
    }
  }
  const std::string text = test::read_text(test::data("cube.mesh"));
  const std::size_t complete = text.rfind("End") + 3;
  for (std::size_t n : accepted_prefixes(text, [](const std::string& t) { return parse_medit(t, "cube.mesh"); })) {
    CAPTURE(n);
    CHECK(n >= complete);
  }
}

TEST_CASE("truncation of a legacy VTK file: an error until the cells are complete, never a wrong grid") {
  // legacy VTK has no end marker: a file cut between two data sections is a valid file without
  // them, so a cut may only lose trailing data arrays, never points or cells
  for (const std::string name : {"sample42_ascii.vtk", "sample51_ascii.vtk", "sample42_binary.vtk", "sample51_binary.vtk"}) {
    CAPTURE(name);
    const std::string text = test::read_text(test::data(name));
    const MeshFile full = parse_vtk(text, name);
    const std::size_t cell_types = text.find("CELL_TYPES");
    for (std::size_t n : accepted_prefixes(text, [&](const std::string& t) { return parse_vtk(t, name); })) {
      CAPTURE(n);
      CHECK(n > cell_types);
      const MeshFile part = parse_vtk(text.substr(0, n), name);
      CHECK(part.mesh.points == full.mesh.points);
      CHECK(part.mesh.conn == full.mesh.conn);
      CHECK(part.mesh.types == full.mesh.types);
    }
  }
}

TEST_CASE("random corruption of every sample throws only IoError, and what parses is consistent") {
  std::mt19937 rng(20240611);
  const std::vector<std::string> names{"two_tets.msh",       "mixed41.msh",        "cube.mesh",         "sample42_ascii.vtk",
                                       "sample51_ascii.vtk", "sample42_binary.vtk", "sample51_binary.vtk"};
  std::string alphabet = "0123456789 -+.e\n$#nanEndNodesCELLS\xff";
  alphabet.push_back('\0');
  std::size_t parsed = 0, rejected = 0;
  for (const auto& name : names) {
    const std::string original = test::read_text(test::data(name));
    for (int iter = 0; iter < 400; ++iter) {
      std::string t = original;
      const int edits = 1 + static_cast<int>(rng() % 4);
      for (int e = 0; e < edits && !t.empty(); ++e) {
        const std::size_t at = rng() % t.size();
        switch (rng() % 4) {
          case 0: t[at] = alphabet[rng() % alphabet.size()]; break;
          case 1: t.erase(at, 1 + rng() % 8); break;
          case 2: t.insert(at, t.substr(rng() % t.size(), 1 + rng() % 12)); break;
          default: t.insert(at, std::to_string(static_cast<std::int64_t>(rng()) * 1000003)); break;
        }
      }
      try {
        const MeshFile f = name.find(".msh") != std::string::npos    ? parse_gmsh(t, name)
                           : name.find(".mesh") != std::string::npos ? parse_medit(t, name)
                                                                     : parse_vtk(t, name);
        ++parsed;
        CHECK_NOTHROW(f.mesh.check_indices(name));
        for (const auto& p : f.mesh.points) CHECK((std::isfinite(p[0]) && std::isfinite(p[1]) && std::isfinite(p[2])));
      } catch (const IoError&) {
        ++rejected;
      }
    }
  }
  MESSAGE("corrupted samples: " << parsed << " parsed, " << rejected << " rejected");
  CHECK(rejected > parsed);
}

}  // namespace test_read_medit_vtk
