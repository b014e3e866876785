// model.groups by Gmsh physical name: each mesh file resolves a name through its own
// $PhysicalNames, so two files that number the same name differently both follow the name;
// a name no mesh declares is refused with the names there are, and MEDIT references (numbers
// only) are said to need `tag`.
#include <doctest/doctest.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <functional>
#include <string>
#include <unistd.h>

#include "sewn/apps/continuum.hpp"
#include "sewn/apps/runner.hpp"
#include "sewn/apps/scene.hpp"

namespace test_group_names {
namespace {

namespace fs = std::filesystem;
using sewn::app::CellModel;

// A tetrahedron (physical "body"), a triangle flap on its edge 1-2 ("flap"), two segments
// hanging from the flap's tip ("cable"), the tetrahedron's bottom face ("bottom", a label) and
// a physical point at the cable's end ("tip", no cell). `flap` and `cable` are the tags the
// file gives those two names, so that two files can number them differently.
std::string tiny_msh(int flap, int cable) {
  const std::string f = std::to_string(flap), c = std::to_string(cable);
  return "$MeshFormat\n2.2 0 8\n$EndMeshFormat\n"
         "$PhysicalNames\n5\n3 1 \"body\"\n2 " + f + " \"flap\"\n1 " + c + " \"cable\"\n2 4 \"bottom\"\n0 5 \"tip\"\n$EndPhysicalNames\n"
         "$Nodes\n7\n1 0 0 0\n2 1 0 0\n3 0 1 0\n4 0 0 1\n5 0.5 -1 0\n6 0.5 -1 -1\n7 0.5 -1 -2\n$EndNodes\n"
         "$Elements\n6\n"
         "1 4 2 1 1 1 2 3 4\n"
         "2 2 2 " + f + " 2 1 2 5\n"
         "3 1 2 " + c + " 3 5 6\n"
         "4 1 2 " + c + " 3 6 7\n"
         "5 2 2 4 4 1 2 3\n"
         "6 15 2 5 5 7\n"
         "$EndElements\n";
}

// A file in a folder of this test's own, removed at the end of the test.
struct TempDir {
  fs::path dir = fs::temp_directory_path() / ("sewn_group_names_" + std::to_string(::getpid()));
  TempDir() { fs::create_directories(dir); }
  ~TempDir() { fs::remove_all(dir); }
  std::string write(const std::string& name, const std::string& text) const {
    std::ofstream(dir / name) << text;
    return (dir / name).string();
  }
};

sewn::app::Scene scene_of(const std::vector<std::string>& files, const std::string& groups) {
  std::string meshes;
  for (const auto& f : files)
    meshes += std::string(meshes.empty() ? "" : ", ") + R"({"type": "file", "path": ")" + f + R"(", "material": "m"})";
  return sewn::app::parse_scene(nlohmann::json::parse(R"({"materials": {"m": {"young": 1e6, "density": 1000}}, "meshes": [)" + meshes +
                                                      R"(], "damping": {"model": "none"}, "model": {"type": "mixed", "groups": )" +
                                                      groups + "}}"),
                                "names.json");
}

std::string reason_of(const std::function<void()>& f) {
  try {
    f();
  } catch (const sewn::app::SceneError& e) {
    return e.path() + ": " + e.reason();
  }
  return "accepted";
}

TEST_CASE("model groups by physical name follow each file's own numbering") {
  TempDir tmp;
  // the same names, numbered 2 / 3 in one file and 3 / 2 in the other
  const std::string a = tmp.write("a.msh", tiny_msh(2, 3)), b = tmp.write("b.msh", tiny_msh(3, 2));
  const auto s = scene_of({a, b}, R"([{"name": "cable", "as": "rod", "radius": 0.01}, {"name": "flap", "as": "label"}])");
  REQUIRE(s.model_groups.size() == 2);
  CHECK(s.model_groups[1].name == "flap");
  const sewn::app::Assembly as = sewn::app::assemble(s);
  // per file: the tetrahedron (solid) and the two cable segments (rod, group 0) are simulated;
  // the flap (named a label) and the bottom face (a face of the tetrahedron) are labels
  REQUIRE(as.mesh.num_cells() == 6);
  for (std::uint32_t c = 0; c < 6; ++c) {
    CAPTURE(c);
    const bool tet = as.mesh.types[c] == sewn::CellType::tetrahedron;
    CHECK(as.model_of_cell[c] == (tet ? CellModel::solid : CellModel::rod));
    CHECK(as.group_of_cell[c] == (tet ? -1 : 0));
  }
  CHECK(as.labels.num_cells() == 4);
  // the group's section reaches the cable of both files: each gets the copy of the material
  // whose area is the circle of radius 0.01
  std::vector<sewn::physics::MaterialParams> materials{{1e6, 0.3, 1000, 0.001, 1e-6, sewn::physics::ElongatedPolicy::refuse}};
  std::vector<std::uint32_t> material_of_cell = as.material_of_cell;
  sewn::app::apply_rod_sections(s, as.mesh, as.model_of_cell, as.group_of_cell, materials, material_of_cell);
  REQUIRE(materials.size() == 2);
  CHECK(materials[1].area == doctest::Approx(3.141592653589793e-4).epsilon(1e-12));
  for (std::uint32_t c = 0; c < 6; ++c) CHECK(material_of_cell[c] == (as.model_of_cell[c] == CellModel::rod ? 1u : 0u));

  // by number, tag 3 is the cable in one file and the flap in the other: a tag follows the number
  const auto by_tag = sewn::app::assemble(scene_of({a, b}, R"([{"tag": 3, "as": "label"}])"));
  // labels: the two bottom faces (embedded), a.msh's two segments and b.msh's flap; simulated:
  // the two tetrahedra, a.msh's flap (a shell) and b.msh's two segments (a rod)
  CHECK(by_tag.labels.num_cells() == 2 + 2 + 1);
  CHECK(by_tag.mesh.num_cells() == 2 + 1 + 2);
  CHECK(std::count(by_tag.model_of_cell.begin(), by_tag.model_of_cell.end(), CellModel::shell) == 1);
}

TEST_CASE("a physical name no cell answers to is refused with what the meshes declare") {
  TempDir tmp;
  const std::string a = tmp.write("a.msh", tiny_msh(2, 3));
  const std::string medit = std::string(SEWN_SOURCE_DIR) + "/tests/apps/data/box_faces.mesh";
  auto error = [](const sewn::app::Scene& s) { return reason_of([&] { (void)sewn::app::assemble(s); }); };
  CHECK(error(scene_of({a}, R"([{"name": "cabel", "as": "rod"}])")) ==
        "model.groups[0].name: no mesh declares a physical name \"cabel\"; the physical names are: meshes[0] (Gmsh MSH): "
        "\"body\" (tag 1, dimension 3), \"flap\" (tag 2, dimension 2), \"cable\" (tag 3, dimension 1), "
        "\"bottom\" (tag 4, dimension 2), \"tip\" (tag 5, dimension 0)");
  CHECK(error(scene_of({a}, R"([{"name": "tip", "as": "label"}])")) ==
        "model.groups[0].name: the physical group \"tip\" has no cell: meshes[0]'s \"tip\" (tag 5, dimension 0) "
        "(0-dimensional groups hold points, which are not simulated cells)");
  // a MEDIT mesh has references, numbers only
  CHECK(error(scene_of({medit}, R"([{"name": "top", "as": "shell"}])")) ==
        "model.groups[0].name: no mesh declares a physical name \"top\"; no mesh of the scene has physical names; "
        "meshes[0] (MEDIT) has numeric tags only (MEDIT references, generated meshes): select their cells with \"tag\"");
  CHECK(error(scene_of({a, medit}, R"([{"name": "top", "as": "shell"}])")).find("; meshes[1] (MEDIT) has numeric tags only") !=
        std::string::npos);
  CHECK(error(scene_of({medit}, R"([{"tag": 3, "as": "label"}])")) == "accepted");  // its references by number
  // a group says tag or name, exactly one of them
  CHECK(reason_of([&] { (void)scene_of({a}, R"([{"tag": 3, "name": "cable", "as": "rod"}])"); }) ==
        "model.groups[0]: give either tag or name, not both");
  CHECK(reason_of([&] { (void)scene_of({a}, R"([{"as": "rod"}])"); }) ==
        "model.groups[0]: give the cells' tag (a number) or name (a Gmsh physical name)");
  CHECK(reason_of([&] { (void)scene_of({a}, R"([{"name": "", "as": "rod"}])"); }) == "model.groups[0].name: the physical name is empty");
}

}  // namespace
}  // namespace test_group_names
