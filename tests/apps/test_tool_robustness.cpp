// The sewn binary on what fuzzing and a new user found (issue 19): paths that cannot be used,
// outputs cut off by a file size limit or a folder the user may not write, and `check` and `run`
// agreeing on bad meshes.
#include <doctest/doctest.h>

#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "sewn_tool.hpp"

namespace fs = std::filesystem;

namespace {

using namespace sewn::test::tool;

const std::string tiny_scene = R"({"materials": {"m": {"young": 1e6, "density": 1000}},
  "meshes": [{"type": "hex_grid", "material": "m", "cells": [1, 1, 1], "size": [0.1, 0.1, 0.1]}],
  "integrator": {"step": 0.001}, "duration": 0.2, "output": {"frames": 200}})";

}  // namespace

TEST_CASE("paths that cannot be used: exit 2 with the path and the reason, before any work") {
  const fs::path scene = tool_write("tiny.json", tiny_scene);
  std::string err;
  const fs::path file = tool_write("a_file", "x");
  CHECK(run_sewn("run --quiet --out " + file.string() + " " + scene.string(), err) == 2);
  CHECK(err.find(file.string() + ": exists and is not a folder") != std::string::npos);
  CHECK(run_sewn("run --quiet --out " + (file / "sub").string() + " " + scene.string(), err) == 2);
  CHECK(err.find(file.string() + "/sub: cannot be created") != std::string::npos);
  const fs::path long_out = tool_scratch(std::string(300, 'o'));
  CHECK(run_sewn("run --quiet --out " + long_out.string() + " " + scene.string(), err) == 2);
  CHECK(err.find("300 bytes") != std::string::npos);
  CHECK(run_sewn("run --quiet --out " + tool_scratch("o1").string() + " " + scene.parent_path().string(), err) == 2);
  CHECK(err.find(scene.parent_path().string() + ": (top level): is a folder, not a scene file") != std::string::npos);
  const fs::path long_scene = scene.parent_path() / (std::string(300, 's') + ".json");
  CHECK(run_sewn("run --quiet " + long_scene.string(), err) == 2);
  CHECK(err.find("File name too long") != std::string::npos);
  // a name that would leave the output folder: refused, and nothing written beside it
  std::string escaping = tiny_scene;
  escaping.insert(1, R"("name": "../escaped", )");
  const fs::path inside = tool_scratch("inside");
  CHECK(run_sewn("run --quiet --out " + inside.string() + " " + tool_write("escape.json", escaping).string(), err) == 2);
  CHECK(err.find("name: must be a plain file name") != std::string::npos);
  CHECK_FALSE(fs::exists(inside.parent_path() / "escaped.pvd"));
  CHECK_FALSE(fs::exists(inside.parent_path() / "escaped.png"));
}

TEST_CASE("past a file size limit the run is exit 1 naming the file, and what it wrote stays valid") {
  const fs::path scene = tool_write("tiny.json", tiny_scene);
  std::string err;
  // 12 kB: each frame (~2.3 kB) fits, frames.csv (~150 bytes a row) outgrows it first
  const fs::path out = tool_scratch("limited");
  fs::remove_all(out);
  CHECK(run_sewn("run --quiet --out " + out.string() + " " + scene.string(), err, "ulimit -f 12; ") == 1);
  CHECK(err.find("cannot write the output: " + (out / "frames.csv").string()) != std::string::npos);
  CHECK(err.find("File too large") != std::string::npos);
  for (const auto& e : fs::directory_iterator(out)) CHECK_MESSAGE(e.path().extension() != ".part", e.path());
  // frames.csv: the header and whole rows only, numbered from 0
  std::istringstream csv(read(out / "frames.csv"));
  std::string line;
  std::getline(csv, line);
  const auto columns = std::count(line.begin(), line.end(), ',') + 1;
  CHECK(columns >= 14);
  int rows = 0;
  while (std::getline(csv, line)) {
    CHECK(std::count(line.begin(), line.end(), ',') + 1 == columns);
    CHECK(line.rfind(std::to_string(rows) + ",", 0) == 0);
    ++rows;
  }
  CHECK(rows > 10);
  CHECK(rows < 201);
  // the series lists only frames whose file is complete
  const std::string pvd = read(out / "tiny.pvd");
  CHECK(pvd.ends_with("</VTKFile>\n"));
  int listed = 0;
  for (std::size_t at = pvd.find("file=\""); at != std::string::npos; at = pvd.find("file=\"", at + 1)) {
    const std::string name = pvd.substr(at + 6, pvd.find('"', at + 6) - at - 6);
    CHECK(read(out / name).ends_with("</VTKFile>\n"));
    ++listed;
  }
  CHECK(listed >= rows);

  // the picture past the limit (frames and csv fit): exit 1 naming it, no picture left
  std::string one_frame = tiny_scene;
  one_frame.replace(one_frame.find("\"frames\": 200"), 13, "\"frames\": 1");
  const fs::path out2 = tool_scratch("limited_png");
  fs::remove_all(out2);
  CHECK(run_sewn("run --quiet --out " + out2.string() + " " + tool_write("pic.json", one_frame).string(), err, "ulimit -f 12; ") == 1);
  CHECK(err.find((out2 / "pic.png").string()) != std::string::npos);
  CHECK_FALSE(fs::exists(out2 / "pic.png"));
  CHECK_FALSE(fs::exists(out2 / "pic.png.part"));
  CHECK(read(out2 / "pic.pvd").find("frame_00001.vtu") != std::string::npos);
}

TEST_CASE("sewn check and sewn run agree on duplicate, inverted, degenerate cells and meshes without cells") {
  struct Case {
    const char* name;
    std::vector<std::string> elements;
    const char* reason;
  };
  const Case cases[] = {
      {"dup_hex", {"5 2 0 0 1 2 3 4 5 6 7 8", "5 2 0 0 2 3 4 1 6 7 8 5"}, "cell 1 (Gmsh element 2, hexahedron) repeats cell 0 (Gmsh element 1)"},
      {"dup_tet", {"4 2 0 0 1 2 4 5", "4 2 0 0 1 2 4 5"}, "cell 1 (Gmsh element 2, tetrahedron) repeats cell 0 (Gmsh element 1)"},
      {"dup_quad", {"3 2 0 0 1 2 3 4", "3 2 0 0 3 4 1 2"}, "cell 1 (Gmsh element 2, quad) repeats cell 0 (Gmsh element 1)"},
      {"dup_segment", {"1 2 0 0 1 2", "1 2 0 0 2 1"}, "cell 1 (Gmsh element 2, segment) repeats cell 0 (Gmsh element 1)"},
      {"no_cells", {}, "the mesh has no cell"},
      {"points_only", {"15 2 0 0 1"}, "the mesh has no cell"},
      // a label (a face of the tetrahedron) first: check numbered the cells it simulates, run
      // the file's, so that the two named one bad cell differently
      {"label_then_inverted", {"2 2 0 0 1 2 4", "4 2 0 0 1 4 2 5"}, "cell 1 (Gmsh element 2, tetrahedron) is inverted"},
      {"label_then_flat", {"2 2 0 0 1 2 5", "4 2 0 0 1 2 5 6"}, "cell 1 (Gmsh element 2, tetrahedron) is degenerate"},
  };
  for (const auto& c : cases) {
    CAPTURE(c.name);
    const fs::path mesh = tool_write(std::string(c.name) + ".msh", cube_msh(c.elements));
    const fs::path scene = tool_write(std::string(c.name) + ".json", R"({"materials": {"m": {"young": 1e6, "density": 1000}},
        "meshes": [{"type": "file", "path": ")" + mesh.string() + R"(", "material": "m"}], "duration": 0.01})");
    std::string check_err, run_err;
    const int check = run_sewn("check " + mesh.string(), check_err);
    const int run = run_sewn("run --quiet --out " + tool_scratch("agree").string() + " " + scene.string(), run_err);
    CHECK(check == 2);
    CHECK(run == 2);
    CHECK_MESSAGE(check_err.find(c.reason) != std::string::npos, check_err);
    CHECK_MESSAGE(run_err.find(c.reason) != std::string::npos, run_err);
  }
}

TEST_CASE("check and run name a bad cell and its points as the file numbers them: sparse node tags, labels first") {
  // node 100 is used by no cell; a label triangle (element 7) comes before the inverted tetrahedron (element 9)
  const fs::path mesh = tool_write("sparse.msh", msh({"100 5 5 5", "10 0 0 0", "20 1 0 0", "30 0 1 0", "40 0 0 1"},
                                                     {"7 2 2 0 0 10 20 30", "9 4 2 0 0 10 30 20 40"}));
  const fs::path scene = tool_write("sparse.json", file_scene("mass-spring", {file_mesh(mesh)}));
  std::string check_err, run_err;
  CHECK(run_sewn("check " + mesh.string(), check_err) == 2);
  CHECK(run_sewn("run --quiet --out " + tool_scratch("sparse").string() + " " + scene.string(), run_err) == 2);
  const std::string reason = "cell 1 (Gmsh element 9, tetrahedron) is inverted";
  const std::string points = "points 10 (0, 0, 0), 30 (0, 1, 0), 20 (1, 0, 0), 40 (0, 0, 1)";
  for (const std::string* err : {&check_err, &run_err}) {
    CHECK_MESSAGE(err->find(reason) != std::string::npos, *err);
    CHECK_MESSAGE(err->find(points) != std::string::npos, *err);
  }
}

TEST_CASE("a cell no model takes is named by its scene mesh, its file and its place there, for every model") {
  // the second mesh: a label triangle (element 11, the prism's bottom face) before a prism
  // (element 12, tag 5); "rod" is the mixed model with tag 5 as rods
  const fs::path prism = tool_write("prism.msh", msh({"1 0 0 0", "2 1 0 0", "3 0 1 0", "4 0 0 1", "5 1 0 1", "6 0 1 1"},
                                                     {"11 2 2 0 0 1 2 3", "12 6 2 5 0 1 2 3 4 5 6"}));
  // a first mesh the model takes
  const std::string tets = R"({"type": "tet_grid", "material": "m", "cells": [1, 1, 1], "size": [1, 1, 1], "origin": [5, 0, 0]})";
  const std::string triangles = R"({"type": "tri_grid", "material": "m", "cells": [1, 1], "size": [1, 1], "origin": [5, 0, 0]})";
  const std::string segments = R"({"type": "polyline", "material": "m", "points": [[5, 0, 0], [6, 0, 0]]})";
  const std::string cell = "cell 1 (Gmsh element 12) of " + prism.string();
  for (const std::string model : {"mass-spring", "solid", "shell", "rod", "mixed"}) {
    CAPTURE(model);
    const std::string& first = model == "shell" ? triangles : model == "rod" ? segments : tets;
    const fs::path scene = tool_write("prism_" + model + ".json", model == "rod" ? file_scene("mixed", {first, file_mesh(prism)}, R"([{"tag": 5, "as": "rod"}])")
                                                                               : file_scene(model, {first, file_mesh(prism)}));
    std::string err;
    CHECK(run_sewn("run --quiet --out " + tool_scratch("prism").string() + " " + scene.string(), err) == 2);
    CHECK_MESSAGE(err.find("meshes[1]") != std::string::npos, err);
    CHECK_MESSAGE(err.find(cell) != std::string::npos, err);
    CHECK_MESSAGE(err.find("prism") != std::string::npos, err);
  }
}

TEST_CASE("a cell the mass-spring model refuses is named as its file numbers it, not as the assembled mesh does") {
  // a 10:1 box (element 5) after a label quad (element 4, its first face), in the second mesh
  const fs::path box = tool_write("long_box.msh", msh({"1 0 0 0", "2 10 0 0", "3 10 1 0", "4 0 1 0", "5 0 0 1", "6 10 0 1", "7 10 1 1", "8 0 1 1"},
                                                      {"4 3 2 0 0 1 2 3 4", "5 5 2 0 0 1 2 3 4 5 6 7 8"}));
  const std::string grid = R"({"type": "hex_grid", "material": "m", "cells": [2, 1, 1], "size": [2, 1, 1], "origin": [0, 5, 0]})";
  const fs::path scene = tool_write("long_box.json", file_scene("mass-spring", {grid, file_mesh(box)}));
  std::string err;
  CHECK(run_sewn("run --quiet --out " + tool_scratch("long_box").string() + " " + scene.string(), err) == 2);
  CHECK_MESSAGE(err.find("meshes[1]: cell 1 (Gmsh element 5) of " + box.string() + " (hexahedron): too elongated") != std::string::npos, err);
}

TEST_CASE("the stable-step refusal names the scene keys, not the library option") {
  std::string err;
  const fs::path scene = tool_write("unstable.json", R"({"materials": {"m": {"young": 1e8, "density": 1000}},
      "meshes": [{"type": "hex_grid", "material": "m", "cells": [2, 1, 1], "size": [0.2, 0.1, 0.1]}],
      "integrator": {"type": "semi-implicit", "step": 0.001}, "duration": 0.01})");
  CHECK(run_sewn("run --quiet --out " + tool_scratch("unstable").string() + " " + scene.string(), err) == 2);
  CHECK(err.find("unstable.json: integrator.step") != std::string::npos);
  CHECK(err.find("integrator.allow_unstable = true") != std::string::npos);
  CHECK(err.find("enforce_stable_step") == std::string::npos);
}

TEST_CASE("a number too large for a double: exit 2 with file and key path, not a failed run") {
  std::string err;
  const fs::path scene = tool_write("inf.json", R"({"materials": {"m": {"young": 1e999, "density": 1000}},
      "meshes": [{"type": "hex_grid", "material": "m", "cells": [1, 1, 1], "size": [0.1, 0.1, 0.1]}]})");
  CHECK(run_sewn("run --quiet --out " + tool_scratch("inf").string() + " " + scene.string(), err) == 2);
  CHECK(err.find(scene.string() + ": materials.m.young: the number 1e999 is out of range") != std::string::npos);
}

TEST_CASE("an output folder the user may not write: exit 1 naming it, the files already there untouched") {
  // root ignores permissions, so the tool runs as nobody (uid/gid 65534) when this is root
  std::string as_user;
  if (::geteuid() == 0) {
    if (std::system("command -v setpriv > /dev/null 2>&1") == 0)
      as_user = "setpriv --reuid=65534 --regid=65534 --clear-groups ";
    else if (std::system("command -v runuser > /dev/null 2>&1") == 0)
      as_user = "runuser -u nobody -- ";
    else {
      MESSAGE("skipped: running as root, and neither setpriv nor runuser exists to drop the privilege");
      return;
    }
  }
  const fs::path scene = tool_write("ro.json", tiny_scene);
  std::string err;
  const fs::path out = tool_scratch("read_only");
  fs::remove_all(out);
  REQUIRE(run_sewn("run --quiet --out " + out.string() + " " + scene.string(), err) == 0);
  const std::string csv_before = read(out / "frames.csv");
  fs::permissions(out, fs::perms::owner_read | fs::perms::owner_exec | fs::perms::group_read | fs::perms::group_exec |
                           fs::perms::others_read | fs::perms::others_exec);
  // the folder exists but is not writable: refused before any work
  CHECK(run_sewn("run --quiet --out " + out.string() + " " + scene.string(), err, as_user) == 1);
  CHECK_MESSAGE(err.find("cannot write the output: " + out.string() + ": cannot be written: Permission denied") != std::string::npos, err);
  CHECK(read(out / "frames.csv") == csv_before);
  // a folder to create inside it
  CHECK(run_sewn("run --quiet --out " + (out / "sub").string() + " " + scene.string(), err, as_user) == 1);
  CHECK_MESSAGE(err.find((out / "sub").string() + ": cannot be created: Permission denied") != std::string::npos, err);
  // a checkpoint to resume there: the same
  CHECK(run_sewn("run --quiet --checkpoint-every 10 --out " + out.string() + " " + scene.string(), err, as_user) == 1);
  CHECK_MESSAGE(err.find("Permission denied") != std::string::npos, err);
  for (const auto& e : fs::directory_iterator(out)) CHECK_MESSAGE(e.path().extension() != ".part", e.path());
  fs::permissions(out, fs::perms::owner_write, fs::perm_options::add);
}
