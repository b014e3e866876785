#include <doctest/doctest.h>

#include "io_test_util.hpp"
#include "sewn/io/geometry.hpp"
#include "sewn/io/read.hpp"

namespace test_read_gmsh {

using namespace sewn;
using namespace sewn::io;
using sewn::io::test::message_of;

namespace {

const std::string header22 = "$MeshFormat\n2.2 0 8\n$EndMeshFormat\n";
const std::string nodes22 = "$Nodes\n4\n1 0 0 0\n2 1 0 0\n3 0 1 0\n4 0 0 1\n$EndNodes\n";

MeshFile parse(const std::string& text) { return parse_gmsh(text, "bad.msh"); }

}  // namespace

TEST_CASE("gmsh 2.2: nodes, elements, physical tags and names; points are skipped and counted") {
  const MeshFile f = read_gmsh(test::data("two_tets.msh"));
  CHECK(f.version == "2.2");
  CHECK(f.mesh.num_points() == 5);
  REQUIRE(f.mesh.num_cells() == 3);
  CHECK(f.file_elements == 4);
  CHECK(f.skipped_points == 1);
  CHECK(f.mesh.types[0] == CellType::triangle);
  CHECK(f.mesh.types[1] == CellType::tetrahedron);
  CHECK(f.mesh.tags == std::vector<std::int32_t>{5, 7, 7});
  const auto t1 = f.mesh.cell(2);
  CHECK(std::vector<std::uint32_t>(t1.begin(), t1.end()) == std::vector<std::uint32_t>{1, 2, 3, 4});
  REQUIRE(f.tag_names.size() == 2);
  CHECK(f.tag_names[1].dimension == 3);
  CHECK(f.tag_names[1].tag == 7);
  CHECK(f.tag_names[1].name == "body");
  CHECK_NOTHROW(check_mesh_geometry(f.mesh, "two_tets.msh"));
}

TEST_CASE("gmsh 4.1: entity blocks, sparse node tags, prisms and pyramids in VTK order") {
  const MeshFile f = read_gmsh(test::data("mixed41.msh"));
  CHECK(f.version == "4.1");
  CHECK(f.mesh.num_points() == 15);
  REQUIRE(f.mesh.num_cells() == 4);
  CHECK(f.mesh.types == std::vector<CellType>{CellType::hexahedron, CellType::prism, CellType::prism, CellType::pyramid});
  CHECK(f.mesh.tags == std::vector<std::int32_t>{10, 20, 20, 30});
  // node tag 10k is point k-1; Gmsh prism 50 60 80 / 90 100 120 becomes VTK 50 80 60 / 90 120 100
  const auto p = f.mesh.cell(1);
  CHECK(std::vector<std::uint32_t>(p.begin(), p.end()) == std::vector<std::uint32_t>{4, 7, 5, 8, 11, 9});
  CHECK(f.tag_names.size() == 3);
  // every cell, converted, is positively oriented in VTK's convention
  CHECK_NOTHROW(check_mesh_geometry(f.mesh, "mixed41.msh"));
}

TEST_CASE("gmsh 2.2: an element repeated for each of its physical groups is read once") {
  // as Gmsh writes an entity that belongs to physical groups 7 and 8
  const std::string text = header22 + nodes22 +
                           "$Elements\n3\n1 1 2 3 1 1 2\n2 3 2 7 1 1 2 3 4\n3 3 2 8 1 1 2 3 4\n$EndElements\n";
  const MeshFile f = parse(text);
  REQUIRE(f.mesh.num_cells() == 2);
  CHECK(f.mesh.tags == std::vector<std::int32_t>{3, 7});
  // the element tags follow the cells kept: a message names the second cell element 2
  CHECK(f.element_tags == std::vector<std::int64_t>{1, 2});
}

TEST_CASE("gmsh: each point keeps its node tag and each cell its element tag, for messages") {
  const std::string text = header22 + "$Nodes\n4\n40 0 0 0\n7 1 0 0\n300 0 1 0\n8 0 0 1\n$EndNodes\n" +
                           "$Elements\n2\n90 15 2 0 0 7\n12 4 2 0 0 40 300 7 8\n$EndElements\n";
  const MeshFile f = parse(text);
  CHECK(f.node_tags == std::vector<std::int64_t>{40, 7, 300, 8});
  CHECK(f.point_numbers() == std::vector<std::int64_t>{40, 7, 300, 8});
  CHECK(f.element_tags == std::vector<std::int64_t>{12});  // the point element 90 is skipped
  // the inverted tetrahedron, named as the file numbers it
  GeometryOptions numbering;
  numbering.point_numbers = f.point_numbers();
  numbering.element_tags = f.element_tags;
  const std::string msg = message_of<InvertedCellError>([&] { check_mesh_geometry(f.mesh, "t.msh", numbering); });
  CHECK(msg.find("t.msh: cell 0 (Gmsh element 12, tetrahedron) is inverted") == 0);
  CHECK(msg.find("points 40 (0, 0, 0), 300 (0, 1, 0), 7 (1, 0, 0), 8 (0, 0, 1)") != std::string::npos);
  // without numbering: indices, as for an API user's mesh
  CHECK(message_of<InvertedCellError>([&] { check_mesh_geometry(f.mesh, "t.msh"); }).find("points 0 (0, 0, 0), 2 (0, 1, 0), 1 (1, 0, 0)") != std::string::npos);
}

TEST_CASE("gmsh: unknown sections are skipped; without physical groups the tag is 0") {
  const std::string text = header22 + "$Comments\nanything $Nodes here\n$EndComments\n" + nodes22 +
                           "$Elements\n1\n1 4 0 1 2 3 4\n$EndElements\n$NodeData\n1\n\"x\"\n$EndNodeData\n";
  const MeshFile f = parse(text);
  REQUIRE(f.mesh.num_cells() == 1);
  CHECK(f.mesh.tags[0] == 0);
}

TEST_CASE("gmsh 4.1: parametric node blocks carry extra coordinates, which are skipped") {
  const std::string text = "$MeshFormat\n4.1 0 8\n$EndMeshFormat\n"
                           "$Nodes\n2 3 1 3\n1 4 1 2\n1\n2\n0 0 0 0.0\n1 0 0 1.0\n2 1 1 1\n3\n0 1 0 0.5 0.5\n$EndNodes\n"
                           "$Elements\n1 1 1 1\n2 1 2 1\n1 1 2 3\n$EndElements\n";
  const MeshFile f = parse(text);
  REQUIRE(f.mesh.num_points() == 3);
  CHECK(f.mesh.points[2] == Point3{0, 1, 0});
  CHECK(f.mesh.types[0] == CellType::triangle);
}

// A tetrahedron's solid (volume 1) and one face (surface 1), as Gmsh 4.1 saves them once a
// physical group exists: only the elements of grouped entities. With only the face grouped the
// solid is silently missing, which the reader says in a warning; grouped, or with no group at
// all (everything saved), nothing is said.
TEST_CASE("gmsh 4.1: a volume in no physical group, whose elements Gmsh did not save, is warned about") {
  auto file = [](const std::string& surface_groups, const std::string& volume_groups, bool with_tet) {
    return "$MeshFormat\n4.1 0 8\n$EndMeshFormat\n$Entities\n0 0 1 1\n"
           "1 0 0 0 1 1 0 " + surface_groups + " 0\n1 0 0 0 1 1 1 " + volume_groups + " 1 1\n$EndEntities\n"
           "$Nodes\n2 4 1 4\n2 1 0 3\n1\n2\n3\n0 0 0\n1 0 0\n0 1 0\n3 1 0 1\n4\n0 0 1\n$EndNodes\n" +
           std::string(with_tet ? "$Elements\n2 2 1 2\n2 1 2 1\n1 1 2 3\n3 1 4 1\n2 1 2 3 4\n$EndElements\n"
                                : "$Elements\n1 1 1 1\n2 1 2 1\n1 1 2 3\n$EndElements\n");
  };
  const MeshFile lost = parse(file("1 5", "0", false));
  CHECK(lost.mesh.num_cells() == 1);
  REQUIRE(lost.warnings.size() == 1);
  CHECK(lost.warnings[0].find("bad.msh: Gmsh saved only the elements of physical groups, and volume 1 of the geometry belongs to none") == 0);
  CHECK(lost.warnings[0].find("Add it to a Physical Volume, or save with Mesh.SaveAll = 1") != std::string::npos);
  CHECK(parse(file("1 5", "1 7", true)).warnings.empty());  // both grouped and saved
  CHECK(parse(file("0", "0", true)).warnings.empty());      // no group: Gmsh saved everything
  CHECK(parse(file("1 5", "0", true)).warnings.empty());    // SaveAll: the ungrouped volume's tetrahedron is there
}

TEST_CASE("gmsh bad input: each problem throws its own exception naming file and line") {
  SUBCASE("empty file") {
    const auto m = message_of<ParseError>([] { parse(""); });
    CHECK(m.find("bad.msh:1: expected '$MeshFormat'") != std::string::npos);
    CHECK(m.find("end of the file") != std::string::npos);
  }
  SUBCASE("not a mesh file") { message_of<ParseError>([] { parse("hello world\n"); }); }
  SUBCASE("unsupported versions") {
    CHECK(message_of<UnsupportedError>([] { parse("$MeshFormat\n3.0 0 8\n$EndMeshFormat\n"); }).find("bad.msh:2:") == 0);
    message_of<UnsupportedError>([] { parse("$MeshFormat\n4 0 8\n$EndMeshFormat\n"); });
    message_of<UnsupportedError>([] { parse("$NOD\n1\n1 0 0 0\n$ENDNOD\n"); });
    message_of<ParseError>([] { parse("$MeshFormat\nfour 0 8\n$EndMeshFormat\n"); });
  }
  SUBCASE("element refers to a node that does not exist") {
    const auto m = message_of<SemanticError>(
        [] { parse(header22 + nodes22 + "$Elements\n1\n7 4 2 0 1 1 2 3 99\n$EndElements\n"); });
    CHECK(m.find("bad.msh:13:") == 0);
    CHECK(m.find("element 7 refers to node 99") != std::string::npos);
  }
  SUBCASE("unknown and higher-order element types") {
    CHECK(message_of<SemanticError>([] { parse(header22 + nodes22 + "$Elements\n1\n1 999 2 0 1 1 2\n$EndElements\n"); })
              .find("bad.msh:13: element 1 has unknown Gmsh element type 999") == 0);
    CHECK(message_of<UnsupportedError>(
              [] { parse(header22 + nodes22 + "$Elements\n1\n1 11 2 0 1 1 2 3 4 1 2 3 4 1 2\n$EndElements\n"); })
              .find("10-node second-order tetrahedron") != std::string::npos);
  }
  SUBCASE("non-finite coordinates") {
    for (const std::string bad : {"nan", "inf", "-inf", "1e999", "NaN"}) {
      const auto m = message_of<SemanticError>(
          [&] { parse(header22 + "$Nodes\n2\n1 0 0 0\n2 0 " + bad + " 0\n$EndNodes\n"); });
      CHECK(m.find("bad.msh:7: node 2 has a non-finite y coordinate") == 0);
    }
  }
  SUBCASE("tiny coordinates underflow to zero rather than failing") {
    const MeshFile f = parse(header22 + "$Nodes\n1\n1 1e-400 0 0\n$EndNodes\n$Elements\n0\n$EndElements\n");
    CHECK(f.mesh.points[0][0] == 0.0);
  }
  SUBCASE("negative counts") {
    CHECK(message_of<ParseError>([] { parse(header22 + "$Nodes\n-3\n"); }).find("bad.msh:5: expected the number of nodes (a non-negative count), found '-3'") == 0);
    message_of<ParseError>([] { parse(header22 + nodes22 + "$Elements\n-1\n$EndElements\n"); });
  }
  SUBCASE("garbage tokens") {
    CHECK(message_of<ParseError>([] { parse(header22 + "$Nodes\n1\n1 0 0 abc\n$EndNodes\n"); })
              .find("bad.msh:6: expected z coordinate of node 1 (a real number), found 'abc'") == 0);
    message_of<ParseError>([] { parse(header22 + "$Nodes\n1\n1 0 0 0 7\n$EndNodes\n"); });
    message_of<ParseError>([] { parse(header22 + nodes22 + "$Elements\n1\n1 4 2 0 1 1 2 3 4 5\n$EndElements\n"); });
    message_of<ParseError>([] { parse(header22 + "\x01\x02\xff garbage"); });
  }
  SUBCASE("a declared count larger than the file") {
    // a huge count must not allocate in proportion to it: the file runs out first
    CHECK(message_of<ParseError>([] { parse(header22 + "$Nodes\n4000000000\n1 0 0 0\n"); }).find("end of the file") !=
          std::string::npos);
    message_of<SemanticError>([] { parse(header22 + "$Nodes\n99999999999999\n1 0 0 0\n"); });
    message_of<SemanticError>([] { parse(header22 + "$Nodes\n99999999999999999999999\n"); });
  }
  SUBCASE("a declared count smaller than the data") {
    CHECK(message_of<ParseError>([] { parse(header22 + "$Nodes\n1\n1 0 0 0\n2 1 0 0\n$EndNodes\n"); })
              .find("bad.msh:7: expected '$EndNodes' after the 1 nodes the section declares, found '2'") == 0);
  }
  SUBCASE("duplicate node tags, a repeated node in an element") {
    message_of<SemanticError>([] { parse(header22 + "$Nodes\n2\n1 0 0 0\n1 1 0 0\n$EndNodes\n"); });
    message_of<SemanticError>([] { parse(header22 + nodes22 + "$Elements\n1\n1 4 0 1 2 3 3\n$EndElements\n"); });
  }
  SUBCASE("sections out of order or missing") {
    message_of<ParseError>([] { parse(header22 + "$Elements\n0\n$EndElements\n"); });
    message_of<ParseError>([] { parse(header22 + nodes22); });
    message_of<ParseError>([] { parse(header22 + "$Comments\nnever closed\n"); });
    message_of<SemanticError>([] { parse(header22 + nodes22 + nodes22); });
  }
  SUBCASE("4.1: inconsistent blocks and entities") {
    const std::string h = "$MeshFormat\n4.1 0 8\n$EndMeshFormat\n";
    const std::string ent = "$Entities\n0 0 0 1\n1 0 0 0 1 1 1 1 5 0\n$EndEntities\n";
    const std::string nodes = "$Nodes\n1 4 1 4\n3 1 0 4\n1\n2\n3\n4\n0 0 0\n1 0 0\n0 1 0\n0 0 1\n$EndNodes\n";
    CHECK(parse(h + ent + nodes + "$Elements\n1 1 1 1\n3 1 4 1\n1 1 2 3 4\n$EndElements\n").mesh.tags[0] == 5);
    // element block on an entity $Entities does not declare
    message_of<SemanticError>([&] { parse(h + ent + nodes + "$Elements\n1 1 1 1\n3 9 4 1\n1 1 2 3 4\n$EndElements\n"); });
    // blocks hold more nodes than declared
    message_of<SemanticError>(
        [&] { parse(h + "$Nodes\n1 3 1 4\n3 1 0 4\n1\n2\n3\n4\n0 0 0\n1 0 0\n0 1 0\n0 0 1\n$EndNodes\n"); });
    // a node tag outside the declared range
    message_of<SemanticError>(
        [&] { parse(h + "$Nodes\n1 2 1 2\n3 1 0 2\n1\n7\n0 0 0\n1 0 0\n$EndNodes\n"); });
    // element count disagrees with the header
    message_of<SemanticError>([&] { parse(h + ent + nodes + "$Elements\n1 2 1 2\n3 1 4 1\n1 1 2 3 4\n$EndElements\n"); });
    // a volume element type in a surface block
    message_of<SemanticError>([&] { parse(h + nodes + "$Elements\n1 1 1 1\n2 1 4 1\n1 1 2 3 4\n$EndElements\n"); });
  }
}

TEST_CASE("read_mesh: missing, empty, directory, unknown content; dispatch by content") {
  test::TempDir dir("dispatch");
  CHECK(message_of<FileError>([&] { read_mesh(dir.path() / "nope.msh"); }).find("nope.msh: no such file") !=
        std::string::npos);
  message_of<FileError>([&] { read_mesh(dir.path()); });
  CHECK(message_of<ParseError>([&] { read_mesh(dir.write("empty.msh", "")); }).find("empty.msh:1: expected a mesh") !=
        std::string::npos);
  message_of<ParseError>([&] { read_mesh(dir.write("blank.vtk", "  \n\n")); });
  message_of<UnsupportedError>([&] { read_mesh(dir.write("what.txt", "solid cube\nfacet normal 0 0 1\n")); });
  message_of<UnsupportedError>([&] { read_mesh(dir.write("bin.meshb", "\x01\x00\x00\x00")); });
  // other tools' files brought as meshes: what to do with them
  CHECK(message_of<UnsupportedError>([&] { read_mesh(dir.write("part.stl", "solid part\nfacet normal 0 0 1\n")); })
            .find("a scene's mesh of type \"surface\" voxelizes") != std::string::npos);
  CHECK(message_of<UnsupportedError>([&] { read_mesh(dir.write("part.1.ele", "4 4 0\n")); }).find("tetgen with -g") != std::string::npos);
  // the content decides, whatever the extension says
  const auto p = dir.write("really_gmsh.vtk", test::read_text(test::data("two_tets.msh")));
  CHECK(read_mesh_file(p).format == MeshFormat::gmsh);
  CHECK(read_mesh(test::data("cube.mesh")).num_cells() == 5);
  CHECK(read_mesh_file(test::data("sample51_binary.vtk")).format == MeshFormat::vtk_legacy);
}

}  // namespace test_read_gmsh
