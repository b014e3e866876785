// What a user of a mesh file reads when sewn refuses it or warns about it: cells and points named
// as the file numbers them (the file's cell index, Gmsh element and node tags) under the scene
// key of the mesh, never by the assembled mesh's numbers (scene meshes put together, labels and
// unused points dropped, elongated boxes split) that the user cannot look up.
#include <doctest/doctest.h>

#include <string>
#include <vector>

#include "sewn_tool.hpp"

namespace test_error_names {

namespace fs = std::filesystem;
using namespace sewn::test::tool;

// A first scene mesh (material m), so that the file's cells and points are not the
// assembled mesh's first ones.
const std::string first_grid = R"({"type": "hex_grid", "material": "m", "cells": [1, 1, 1], "size": [1, 1, 1], "origin": [0, 5, 0]})";

// Three tetrahedra on the triangle (10, 20, 30), the first two on either side and the third on
// the first one's side; node 100 is used by no cell and a label triangle (element 7) comes first.
std::vector<std::string> three_on_a_face(bool with_second) {
  std::vector<std::string> elements = {"7 2 2 0 0 10 20 30", "9 4 2 0 0 10 20 30 40"};
  if (with_second) elements.push_back("11 4 2 0 0 10 30 20 50");
  elements.push_back("13 4 2 0 0 10 20 30 60");
  return elements;
}
const std::vector<std::string> face_nodes = {"100 5 5 5", "10 0 0 0", "20 1 0 0", "30 0 1 0", "40 0 0 1", "50 0 0 -1", "60 0.2 0.2 2"};

TEST_CASE("the map builder's refusals name the file's cells: a face of three volumes, two volumes on one side of a face") {
  const fs::path three = tool_write("three_on_face.msh", msh(face_nodes, three_on_a_face(true)));
  const fs::path scene = tool_write("three_on_face.json", file_scene("mass-spring", {first_grid, file_mesh(three)}));
  std::string err;
  CHECK(run_sewn("run --quiet --out " + tool_scratch("three").string() + " " + scene.string(), err) == 2);
  // the assembled mesh called them cells 2 and 3 (the grid's hexahedron first, the label dropped)
  const std::string in = " of " + three.string();
  CHECK_MESSAGE(err.find(scene.string() + ": meshes[1]: 3 cells share one face, among them cell 1 (Gmsh element 9)" + in +
                         " (tetrahedron) and cell 2 (Gmsh element 11)" + in + " (tetrahedron)") != std::string::npos,
                err);

  // sewn check reports the face's points by their node tags (were their places in the file: 1, 2, 3)
  std::string check_err;
  CHECK(run_sewn("check " + three.string(), check_err) == 0);
  for (const char* node : {"10", "20", "30"})
    CHECK_MESSAGE(check_err.find("vertex at point " + std::string(node) + ": a face at it lies in 3 volumes") != std::string::npos, check_err);
  CHECK_MESSAGE(check_err.find("vertex at point 1:") == std::string::npos, check_err);

  // without the tetrahedron below, the other two overlap: check and run say the same of it
  const fs::path two = tool_write("two_on_face.msh", msh(face_nodes, three_on_a_face(false)));
  const fs::path scene2 = tool_write("two_on_face.json", file_scene("mass-spring", {first_grid, file_mesh(two)}));
  CHECK(run_sewn("run --quiet --out " + tool_scratch("two").string() + " " + scene2.string(), err) == 2);
  CHECK(run_sewn("check " + two.string(), check_err) == 2);
  const std::string of = " of " + two.string();
  const std::string cells = "cell 1 (Gmsh element 9)" + of + " (tetrahedron) and cell 2 (Gmsh element 13)" + of +
                            " (tetrahedron) share a face with the same orientation: both lie on the same side of it";
  CHECK_MESSAGE(err.find(scene2.string() + ": meshes[1]: " + cells) != std::string::npos, err);
  CHECK_MESSAGE(check_err.find(two.string() + ": " + cells) != std::string::npos, check_err);
}

TEST_CASE("the split into near-cubes names the file's cells and nodes when it refuses a cell") {
  // a 10:1 box (element 5) after a label quad (element 4, its bottom face), and a tetrahedron
  // (element 7) on its long edge from node 11 to node 12, which the split would cut
  const fs::path file = tool_write("split_refused.msh",
                                   msh({"100 5 5 5", "11 0 0 0", "12 10 0 0", "13 10 1 0", "14 0 1 0", "15 0 0 1", "16 10 0 1", "17 10 1 1",
                                        "18 0 1 1", "19 5 -1 0", "20 5 -0.5 -1"},
                                       {"4 3 2 0 0 11 14 13 12", "5 5 2 0 0 11 12 13 14 15 16 17 18", "7 4 2 0 0 11 12 19 20"}));
  const fs::path scene = tool_write("split_refused.json", R"({"materials": {"m": {"young": 1e6, "density": 1000},
      "s": {"young": 1e6, "density": 1000, "elongated": "split"}},
      "meshes": [)" + first_grid + ", " + file_mesh(file, "s") + R"(], "duration": 0.01})");
  std::string err;
  CHECK(run_sewn("run --quiet --out " + tool_scratch("split_refused").string() + " " + scene.string(), err) == 2);
  const std::string of = " of " + file.string();
  CHECK_MESSAGE(err.find(scene.string() + ": meshes[1]: cell 2 (Gmsh element 7)" + of + " (tetrahedron) shares the edge from point 11" + of +
                         " to point 12" + of) != std::string::npos,
                err);
  CHECK_MESSAGE(err.find("because the hexahedron cell 1 (Gmsh element 5)" + of + ", 10:1, is too elongated") != std::string::npos, err);
}

TEST_CASE("a mass out of range names the file's node and the scene's material") {
  const fs::path file = tool_write("light.msh", msh({"100 5 5 5", "10 0 0 0", "20 1 0 0", "30 0 1 0", "40 0 0 1"},
                                                    {"7 2 2 0 0 10 20 30", "9 4 2 0 0 10 20 30 40"}));
  const fs::path scene = tool_write("light.json", R"({"materials": {"m": {"young": 1e6, "density": 1000}, "light": {"young": 1e6, "density": 1e-320}},
      "meshes": [)" + first_grid + ", " + file_mesh(file, "light") + R"(], "duration": 0.01})");
  std::string err;
  CHECK(run_sewn("run --quiet --out " + tool_scratch("light").string() + " " + scene.string(), err) == 2);
  const std::string of = " of " + file.string();
  CHECK_MESSAGE(err.find(scene.string() + ": meshes[1]: cell 1 (Gmsh element 9)" + of + " (tetrahedron, material \"light\"): its point 10" + of +
                         " gets a mass of") != std::string::npos,
                err);
}

TEST_CASE("an inverted element is named by its scene mesh and cell, a piece of a split cell as such") {
  // a column of 2:1 boxes split into cubes, its lower half 10^6 times softer than the top: its
  // first piece turns inside out
  const fs::path scene = tool_write("split_column.json", R"({"materials": {"soft": {"young": 1e3, "density": 1000, "elongated": "split"},
      "stiff": {"young": 1e9, "density": 1000, "elongated": "split"}},
    "meshes": [{"type": "hex_grid", "cells": [2, 2, 3], "size": [0.1, 0.1, 0.3], "material": "stiff",
                "regions": [{"where": {"type": "box", "min": [-1, -1, -1], "max": [1, 1, 0.15]}, "material": "soft"}]}],
    "fixed": [{"where": {"type": "box", "min": [-1, -1, -1], "max": [1, 1, 0.001]}}],
    "integrator": {"type": "implicit", "step": 0.001, "max_iterations": 10000, "stop_on_inversion": true}, "duration": 0.5,
    "output": {"frames": 10, "vtu": false, "picture": {"enabled": false}}})");
  std::string err;
  CHECK(run_sewn("run --quiet --out " + tool_scratch("split_column").string() + " " + scene.string(), err) == 1);
  CHECK_MESSAGE(err.find("element 0 (meshes[0] piece 0 of cell 0) is inverted at step") != std::string::npos, err);
}

TEST_CASE("point selectors name the entry, and the file's node of the scene point they gave") {
  // after the grid's 8 points: nodes 10, 20, 30, 40 (the tetrahedron), 60, 70 (a segment the
  // scene makes a label), node 100 used by no cell
  const fs::path file = tool_write("selected.msh", msh({"100 5 5 5", "10 0 0 0", "20 1 0 0", "30 0 1 0", "40 0 0 1", "60 2 0 0", "70 3 0 0"},
                                                       {"9 4 2 1 0 10 20 30 40", "12 1 2 2 0 60 70"}));
  auto scene_with = [&](const std::string& name, const std::string& keys) {
    return tool_write(name + ".json", file_scene("mass-spring", {first_grid, file_mesh(file)}, R"([{"tag": 2, "as": "label"}])", keys));
  };
  const std::string of = " of " + file.string();
  std::string err;
  // scene point 12 is node 60, on the label alone
  const fs::path label = scene_with("selected_label", R"("fixed": [{"where": {"type": "points", "indices": [8, 12]}}], )");
  CHECK(run_sewn("run --quiet --out " + tool_scratch("selected").string() + " " + label.string(), err) == 2);
  CHECK_MESSAGE(err.find("fixed[0].where.indices[1]: point 12 (meshes[1] point 60" + of + ") is a point of labels only") != std::string::npos, err);
  const fs::path past = scene_with("selected_past", R"("velocities": [{"where": {"type": "points", "indices": [99]}, "linear": [1, 0, 0]}], )");
  CHECK(run_sewn("run --quiet --out " + tool_scratch("selected").string() + " " + past.string(), err) == 2);
  CHECK_MESSAGE(err.find("velocities[0].where.indices[0]: point 99 is past the scene's 14 points (numbered from 0, over the scene's meshes") !=
                    std::string::npos,
                err);
  // scene point 11 is node 40: held and driven
  const fs::path both = scene_with("selected_both", R"("fixed": [{"where": {"type": "points", "indices": [11]}}],
      "motion": [{"where": {"type": "points", "indices": [11]}, "velocity": [1, 0, 0]}], )");
  CHECK(run_sewn("run --quiet --out " + tool_scratch("selected").string() + " " + both.string(), err) == 2);
  CHECK_MESSAGE(err.find("motion[0].where: selects the particle at meshes[1] point 40" + of + ", which `fixed` holds") != std::string::npos, err);
  // two motions at once
  const fs::path twice = scene_with("selected_twice", R"("motion": [{"where": {"type": "points", "indices": [11]}, "velocity": [1, 0, 0]},
      {"where": {"type": "points", "indices": [10, 11]}, "velocity": [0, 1, 0]}], )");
  CHECK(run_sewn("run --quiet --out " + tool_scratch("selected").string() + " " + twice.string(), err) == 2);
  CHECK_MESSAGE(err.find("motion[1].where: drives the particle at meshes[1] point 40" + of + ", which motion[0] drives") != std::string::npos, err);
}

TEST_CASE("an explicit connection where no mesh point is names the nearest one as its file numbers it") {
  // the fin scene, its mesh file by its full path, a joint asked for far from the body
  std::string text = read(fs::path(SEWN_SOURCE_DIR) / "scenes" / "mixed_fin.json");
  const std::string fin = (fs::path(SEWN_SOURCE_DIR) / "scenes" / "meshes" / "fin.msh").string();
  const auto replace = [&](const std::string& from, const std::string& to) {
    const std::size_t at = text.find(from);
    REQUIRE(at != std::string::npos);
    text.replace(at, from.size(), to);
  };
  replace("\"meshes/fin.msh\"", "\"" + fin + "\"");
  replace(R"("connections": { "detect": true })", R"("connections": {"detect": false, "explicit": [{"kind": "point", "at": [5, 5, 5]}]})");
  const fs::path scene = tool_write("far_joint.json", text);
  std::string err;
  CHECK(run_sewn("run --quiet --out " + tool_scratch("far_joint").string() + " " + scene.string(), err) == 2);
  CHECK_MESSAGE(err.find("model.connections.explicit[0].at: no mesh point is there: the nearest is meshes[0] point ") != std::string::npos, err);
  CHECK_MESSAGE(err.find(" of " + fin + " at [") != std::string::npos, err);
}

TEST_CASE("a blow-up names its particle's point as the file numbers it") {
  // one stiff tetrahedron, its apex (scene point 3, node 40) thrown at 10 m/s, stepped far past
  // the semi-implicit stable step: the apex is the fastest particle when the energy blows up
  const fs::path file = tool_write("blow.msh", msh({"100 5 5 5", "10 0 0 0", "20 1 0 0", "30 0 1 0", "40 0 0 1"}, {"9 4 2 0 0 10 20 30 40"}));
  const fs::path scene = tool_write("blow.json", R"({"materials": {"m": {"young": 1e9, "density": 1000}}, "meshes": [)" + file_mesh(file) + R"(],
      "velocities": [{"where": {"type": "points", "indices": [3]}, "linear": [0, 0, 10]}],
      "integrator": {"type": "semi-implicit", "step": 0.1, "allow_unstable": true}, "duration": 100,
      "output": {"frames": 2, "vtu": false, "picture": {"enabled": false}}})");
  std::string err;
  CHECK(run_sewn("run --quiet --out " + tool_scratch("blow").string() + " " + scene.string(), err) == 1);
  CHECK_MESSAGE(err.find("fastest node 3 ") != std::string::npos, err);
  CHECK_MESSAGE(err.find("; node 3 is a particle at meshes[0] point 40 of " + file.string()) != std::string::npos, err);
}

}  // namespace test_error_names
