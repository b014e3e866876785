// The sewn tool: the default scene's physics as recorded in frames.csv, and the catalogue of bad
// input, each with its exact error class (in process) and a non-zero exit (the binary).
#include <doctest/doctest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "sewn/apps/runner.hpp"
#include "sewn/io/errors.hpp"
#include "sewn/io/geometry.hpp"
#include "sewn/physics/errors.hpp"

namespace fs = std::filesystem;
using namespace sewn::app;

namespace {

fs::path scratch(const std::string& name) {
  const fs::path p = fs::temp_directory_path() / ("sewn_test_apps_" + std::to_string(::getpid())) / name;
  fs::create_directories(p.parent_path());
  return p;
}

void write(const fs::path& p, const std::string& text) {
  std::ofstream out(p);
  out << text;
}

std::vector<std::vector<double>> read_csv(const fs::path& p, std::vector<std::string>& header) {
  std::ifstream in(p);
  std::string line;
  std::getline(in, line);
  std::stringstream h(line);
  for (std::string c; std::getline(h, c, ',');) header.push_back(c);
  std::vector<std::vector<double>> rows;
  while (std::getline(in, line)) {
    std::stringstream s(line);
    std::vector<double> row;
    for (std::string c; std::getline(s, c, ',');) row.push_back(std::stod(c));
    rows.push_back(row);
  }
  return rows;
}

// A Gmsh 2.2 file: `nodes` as "x y z" lines, `elements` as "type tags... nodes" lines.
std::string msh(const std::vector<std::string>& nodes, const std::vector<std::string>& elements) {
  std::string s = "$MeshFormat\n2.2 0 8\n$EndMeshFormat\n$Nodes\n" + std::to_string(nodes.size()) + "\n";
  for (std::size_t i = 0; i < nodes.size(); ++i) s += std::to_string(i + 1) + " " + nodes[i] + "\n";
  s += "$EndNodes\n$Elements\n" + std::to_string(elements.size()) + "\n";
  for (std::size_t i = 0; i < elements.size(); ++i) s += std::to_string(i + 1) + " " + elements[i] + "\n";
  return s + "$EndElements\n";
}

const std::vector<std::string> cube_nodes = {"0 0 0", "1 0 0", "1 1 0", "0 1 0", "0 0 1", "1 0 1", "1 1 1", "0 1 1"};

// A scene with one file mesh.
std::string file_scene(const fs::path& mesh) {
  return R"({"materials": {"m": {"young": 1e6, "density": 1000}},
             "meshes": [{"type": "file", "path": ")" +
         mesh.string() + R"(", "material": "m"}], "duration": 0.01})";
}

template <class Error>
void expect_run_error(const std::string& scene_text, const std::string& needle) {
  const fs::path scene = scratch("scene.json");
  write(scene, scene_text);
  RunOptions opt;
  opt.quiet = true;
  opt.out = scratch("out");
  try {
    run(load_scene(scene.string()), opt);
    FAIL("accepted bad input; expected an error containing \"" << needle << "\"");
  } catch (const Error& e) {
    CAPTURE(std::string(e.what()));
    CHECK(std::string(e.what()).find(needle) != std::string::npos);
  }
}

// Runs the sewn binary; returns its exit code and fills `err` with what it printed.
int run_binary(const std::string& args, std::string& err) {
  const fs::path log = scratch("stderr.txt");
  const std::string cmd = std::string(SEWN_BINARY) + " " + args + " > /dev/null 2> " + log.string();
  const int status = std::system(cmd.c_str());
  std::ifstream in(log);
  err.assign(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
  return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

}  // namespace

TEST_CASE("the default scene runs to the end and its energies behave physically") {
  RunOptions opt;
  opt.quiet = true;
  opt.out = scratch("default");
  const RunSummary s = run(default_scene(), opt);
  CHECK(s.cuts == 1);
  CHECK(s.frames == 81);
  CHECK(fs::exists(s.pvd));
  CHECK(fs::exists(s.picture));
  std::vector<std::string> header;
  const auto rows = read_csv(s.csv, header);
  REQUIRE(rows.size() == 81);
  auto col = [&](const std::string& name) {
    const auto it = std::find(header.begin(), header.end(), name);
    REQUIRE(it != header.end());
    return static_cast<std::size_t>(it - header.begin());
  };
  const std::size_t ke = col("kinetic_energy"), pe = col("potential_energy"), cuts = col("cuts"), particles = col("particles");
  double ke_max = 0;
  for (const auto& r : rows) ke_max = std::max(ke_max, r[ke]);
  CHECK(ke_max > 0);
  // the beam comes to rest: three orders of magnitude below its fastest swing
  CHECK(rows.back()[ke] < 1e-3 * ke_max);
  // no energy from nowhere: implicit Euler and drag dissipate, and a cut only redistributes
  // stiffness (split springs keep their stretch), so kinetic + potential never rises; allowance:
  // the CG tolerance (1e-6 relative per step) on the energy moved in a frame
  for (std::size_t f = 1; f < rows.size(); ++f) {
    const double before = rows[f - 1][ke] + rows[f - 1][pe], after = rows[f][ke] + rows[f][pe];
    CAPTURE(f);
    CHECK(after <= before + 1e-6 * ke_max);
  }
  // the cut happened once, at the start of the first step from 0.6 s (so after the 0.6 s frame),
  // and duplicated particles
  for (const auto& r : rows) CHECK(r[cuts] == (r[col("time")] <= 0.6 + 1e-9 ? 0.0 : 1.0));
  CHECK(rows.back()[particles] > rows.front()[particles]);
}

TEST_CASE("bad input: each problem gives its own error class") {
  const fs::path mesh = scratch("mesh.msh");
  SUBCASE("missing scene file") {
    CHECK_THROWS_WITH_AS(load_scene("/nonexistent/scene.json"), doctest::Contains("no such file"), SceneError);
  }
  SUBCASE("missing mesh file") {
    expect_run_error<sewn::io::FileError>(file_scene(scratch("absent.msh")), "absent.msh");
  }
  SUBCASE("truncated .msh") {
    std::string text = msh(cube_nodes, {"5 2 0 0 1 2 3 4 5 6 7 8"});
    write(mesh, text.substr(0, text.find("$Elements") + 14));
    expect_run_error<sewn::io::ParseError>(file_scene(mesh), "mesh.msh");
  }
  SUBCASE("element index out of range") {
    write(mesh, msh(cube_nodes, {"5 2 0 0 1 2 3 4 5 6 7 99"}));
    expect_run_error<sewn::io::SemanticError>(file_scene(mesh), "99");
  }
  SUBCASE("inverted tetrahedron") {
    write(mesh, msh(cube_nodes, {"4 2 0 0 1 3 2 5"}));  // (0,2,1,4): negative volume
    expect_run_error<sewn::io::InvertedCellError>(file_scene(mesh), "cell 0");
  }
  SUBCASE("zero-volume hexahedron") {
    std::vector<std::string> flat = cube_nodes;
    for (int k = 4; k < 8; ++k) flat[static_cast<std::size_t>(k)] = flat[static_cast<std::size_t>(k - 4)];
    flat[4] = "0 0 1e-300";  // distinct points, no volume
    write(mesh, msh(flat, {"5 2 0 0 1 2 3 4 5 6 7 8"}));
    expect_run_error<sewn::io::DegenerateCellError>(file_scene(mesh), "cell 0");
  }
  SUBCASE("NaN coordinates") {
    std::vector<std::string> bad = cube_nodes;
    bad[6] = "1 nan 1";
    write(mesh, msh(bad, {"5 2 0 0 1 2 3 4 5 6 7 8"}));
    expect_run_error<sewn::io::IoError>(file_scene(mesh), "mesh.msh:12: node 7 has a non-finite y coordinate");
  }
  SUBCASE("a face of three tetrahedra, where a solid is required") {
    write(mesh, msh({"0 0 0", "1 0 0", "0 1 0", "0 0 1", "0 0 -1", "0.3 0.3 0.5"},
                    {"4 2 0 0 1 2 3 4", "4 2 0 0 1 3 2 5", "4 2 0 0 1 2 3 6"}));
    expect_run_error<sewn::MeshError>(file_scene(mesh), "non-manifold");
  }
  SUBCASE("an element Baudet's stiffness cannot model") {
    expect_run_error<sewn::physics::InputError>(
        R"({"materials": {"m": {"young": 1e6, "density": 1000}},
            "meshes": [{"type": "hex_grid", "material": "m", "cells": [2, 1, 1], "size": [1, 0.1, 0.1]}]})",
        "elongated");
  }
  SUBCASE("a semi-implicit step above the stable bound") {
    expect_run_error<sewn::physics::StabilityError>(
        R"({"materials": {"m": {"young": 1e8, "density": 1000}},
            "meshes": [{"type": "hex_grid", "material": "m", "cells": [2, 1, 1], "size": [0.2, 0.1, 0.1]}],
            "integrator": {"type": "semi-implicit", "step": 0.001}, "duration": 0.01})",
        "bound");
  }
  SUBCASE("a fixed region that selects nothing, a cut that crosses nothing") {
    expect_run_error<SceneError>(
        R"({"materials": {"m": {"young": 1e6, "density": 1000}},
            "meshes": [{"type": "hex_grid", "material": "m", "cells": [2, 1, 1], "size": [0.2, 0.1, 0.1]}],
            "fixed": [{"where": {"type": "box", "min": [5, 5, 5], "max": [6, 6, 6]}}]})",
        "fixed[0].where");
    expect_run_error<SceneError>(
        R"({"materials": {"m": {"young": 1e6, "density": 1000}},
            "meshes": [{"type": "hex_grid", "material": "m", "cells": [2, 1, 1], "size": [0.2, 0.1, 0.1]}],
            "duration": 0.01, "cuts": [{"type": "plane", "time": 0, "point": [5, 0, 0], "normal": [1, 0, 0]}]})",
        "cuts[0]");
    expect_run_error<SceneError>(
        R"({"materials": {"m": {"young": 1e6, "density": 1000}},
            "meshes": [{"type": "boxes", "material": "m", "spacing": [1, 1, 1],
                        "boxes": [{"min": [-1000000, -1000000, 0], "max": [1000000, 1000000, 1]}]}]})",
        "scene.json: meshes[0].boxes");
    expect_run_error<SceneError>(
        R"({"materials": {"m": {"young": 1e6, "density": 1000}},
            "meshes": [{"type": "polyline", "material": "m", "points": [[0, 0, 0], [0, 0, 0]]}]})",
        "scene.json: meshes[0].points");
  }
}

TEST_CASE("the sewn binary: exit codes and messages") {
  std::string err;
  CHECK(run_binary("--help", err) == 0);
  CHECK(run_binary("run --help", err) == 0);
  CHECK(run_binary("check --help", err) == 0);
  CHECK(run_binary("frobnicate", err) == 2);
  CHECK(err.find("unknown command") != std::string::npos);
  CHECK(run_binary("run /nonexistent.json", err) == 2);
  CHECK(err.find("/nonexistent.json") != std::string::npos);
  CHECK(run_binary("run --frames zero", err) == 2);
  CHECK(err.find("--frames") != std::string::npos);
  CHECK(run_binary("run --until 0", err) == 2);
  CHECK(err.find("--until") != std::string::npos);
  const fs::path scene = scratch("typo.json");
  write(scene, R"({"materials": {"m": {"yung": 1e6, "density": 1000}}, "meshes": []})");
  CHECK(run_binary("run " + scene.string(), err) == 2);
  CHECK(err.find("materials.m.yung") != std::string::npos);
  CHECK(err.find("did you mean \"young\"") != std::string::npos);
  const fs::path mesh = scratch("check.msh");
  write(mesh, msh(cube_nodes, {"5 2 0 0 1 2 3 4 5 6 7 8"}));
  CHECK(run_binary("check " + mesh.string(), err) == 0);
  write(mesh, msh(cube_nodes, {"4 2 0 0 1 3 2 5"}));
  CHECK(run_binary("check " + mesh.string(), err) == 2);
  // a run that fails: NaN injected by an absurd gravity overflows the positions
  write(scene, R"({"materials": {"m": {"young": 1e6, "density": 1000}},
                   "meshes": [{"type": "hex_grid", "material": "m", "cells": [1, 1, 1], "size": [0.1, 0.1, 0.1]}],
                   "gravity": [0, 0, -1e300], "integrator": {"step": 1}, "duration": 10})");
  CHECK(run_binary("run --quiet --out " + scratch("nan").string() + " " + scene.string(), err) == 1);
  CHECK(err.find("the run failed") != std::string::npos);
}

TEST_CASE("model solid: finite-element tetrahedra replace the springs, stepped by Newton; misuse is named") {
  auto scene = [](const std::string& mesh_type, const std::string& damping, const std::string& extra) {
    return R"({"materials": {"m": {"young": 1e6, "poisson": 0.3, "density": 1000}},
               "meshes": [{"type": ")" + mesh_type + R"(", "material": "m", "cells": [4, 1, 1], "size": [0.4, 0.1, 0.1]}],
               "fixed": [{"where": {"type": "box", "min": [-1, -1, -1], "max": [0.001, 1, 1]}}],
               "model": {"type": "solid", "law": "stvk"}, "damping": )" + damping + R"(,
               "integrator": {"type": "newton", "step": 0.005}, "duration": 0.1, "output": {"frames": 2, "picture": {"width": 200, "height": 150}})" +
           extra + "}";
  };
  const std::string rayleigh = R"({"model": "rayleigh", "alpha": 1.0})";
  SUBCASE("runs, with no spring left and elastic energy from the tetrahedra") {
    const fs::path file = scratch("solid.json");
    write(file, scene("tet_grid", rayleigh, ""));
    RunOptions opt;
    opt.quiet = true;
    opt.out = scratch("solid_out");
    const RunSummary sum = run(load_scene(file.string()), opt);
    CHECK(sum.steps == 20);
    std::vector<std::string> header;
    const auto rows = read_csv(sum.csv, header);
    const auto col = [&](const std::string& name) {
      return static_cast<std::size_t>(std::find(header.begin(), header.end(), name) - header.begin());
    };
    REQUIRE(col("elastic_energy") < header.size());
    CHECK(rows.back()[col("springs")] == 0.0);
    CHECK(rows.back()[col("elements")] == 24.0);
    CHECK(rows.back()[col("elastic_energy")] > 0.0);
    CHECK(std::isfinite(rows.back()[col("kinetic_energy")]));
  }
  SUBCASE("hexahedra") {
    expect_run_error<SceneError>(scene("hex_grid", rayleigh, ""), "needs tetrahedra only");
  }
  SUBCASE("shell: membranes and hinges on a triangle mesh; a volume mesh is refused") {
    std::string text = scene("tri_grid", rayleigh, "");
    text.replace(text.find(R"("solid", "law": "stvk")"), 22, R"("shell")");
    text.replace(text.find(R"("cells": [4, 1, 1], "size": [0.4, 0.1, 0.1])"), 43, R"("cells": [4, 1], "size": [0.4, 0.1])");
    const fs::path file = scratch("shell.json");
    write(file, text);
    RunOptions opt;
    opt.quiet = true;
    opt.out = scratch("shell_out");
    const RunSummary sum = run(load_scene(file.string()), opt);
    std::vector<std::string> header;
    const auto rows = read_csv(sum.csv, header);
    const auto col = [&](const std::string& name) {
      return static_cast<std::size_t>(std::find(header.begin(), header.end(), name) - header.begin());
    };
    CHECK(rows.back()[col("springs")] == 0.0);
    CHECK(rows.back()[col("elements")] == 8.0);
    CHECK(rows.back()[col("elastic_energy")] > 0.0);
    std::string hex = scene("tet_grid", rayleigh, "");
    hex.replace(hex.find(R"("solid", "law": "stvk")"), 22, R"("shell")");
    expect_run_error<SceneError>(hex, "needs triangles only");
  }
  SUBCASE("per-spring damping") {
    expect_run_error<SceneError>(scene("tet_grid", R"({"model": "viscous"})", ""), "per-spring damping");
  }
  SUBCASE("cuts") {
    expect_run_error<SceneError>(
        scene("tet_grid", rayleigh, R"(, "cuts": [{"type": "plane", "time": 0.05, "point": [0.2, 0, 0], "normal": [1, 0, 0]}])"),
        "cutting is not supported");
  }
}
