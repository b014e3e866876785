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

#include <Eigen/Core>

#include "sewn/apps/runner.hpp"
#include "sewn/io/errors.hpp"
#include "sewn/io/geometry.hpp"
#include "sewn/physics/errors.hpp"
#include "sewn/physics/solve/blas_kernels.hpp"
#include "sewn/physics/solve/linear_solver.hpp"
#include "scratch.hpp"

namespace fs = std::filesystem;
namespace test_run {

using namespace sewn::app;

namespace {

fs::path scratch(const std::string& name) { return sewn::test::scratch("run/" + name); }

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

// Runs the sewn binary (with the shell's variable assignments `env` before it); returns its exit
// code and fills `err` with what it printed.
int run_binary(const std::string& args, std::string& err, const std::string& env = "") {
  const fs::path log = scratch("stderr.txt");
  const std::string cmd = env + " " + std::string(SEWN_BINARY) + " " + args + " > /dev/null 2> " + log.string();
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
  const std::size_t ke = col("kinetic_energy"), el = col("elastic_energy"), gr = col("gravity_energy"), total = col("total_energy"),
                    work = col("external_work"), lost = col("dissipated"), cuts = col("cuts"), particles = col("particles");
  double ke_max = 0;
  for (const auto& r : rows) ke_max = std::max(ke_max, r[ke]);
  CHECK(ke_max > 0);
  // the beam comes to rest: three orders of magnitude below its fastest swing
  CHECK(rows.back()[ke] < 1e-3 * ke_max);
  // no energy from nowhere: implicit Euler and drag dissipate, and a cut only redistributes
  // stiffness (split springs keep their stretch), so kinetic + potential never rises; allowance:
  // the CG tolerance (1e-6 relative per step) on the energy moved in a frame
  for (std::size_t f = 1; f < rows.size(); ++f) {
    const double before = rows[f - 1][total], after = rows[f][total];
    CAPTURE(f);
    CHECK(after <= before + 1e-6 * ke_max);
  }
  // the columns add up: the total is its three parts, and kinetic + elastic is its start value
  // plus the work of gravity minus what was dissipated (to the CSV's printed precision)
  for (const auto& r : rows) {
    const double scale = std::abs(r[total]) + std::abs(r[gr]) + std::abs(r[work]);
    CHECK(r[total] == doctest::Approx(r[ke] + r[el] + r[gr]).epsilon(1e-9).scale(scale));
    CHECK(r[ke] + r[el] == doctest::Approx(rows[0][ke] + rows[0][el] + r[work] - r[lost]).epsilon(1e-9).scale(scale));
    CHECK(r[lost] >= -1e-6 * ke_max);  // implicit Euler and drag only remove energy
  }
  CHECK(rows.back()[col("energy_rises")] == 0.0);
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
  // a run that fails: a semi-implicit step far above its stable bound, explicitly allowed, blows
  // up (an absurd gravity, which did this before, is now refused as bad input)
  write(scene, R"({"materials": {"m": {"young": 1e8, "density": 1000}},
                   "meshes": [{"type": "hex_grid", "material": "m", "cells": [2, 2, 2], "size": [0.2, 0.2, 0.2]}],
                   "integrator": {"type": "semi-implicit", "step": 0.001, "allow_unstable": true}, "duration": 10})");
  CHECK(run_binary("run --quiet --out " + scratch("nan").string() + " " + scene.string(), err) == 1);
  CHECK(err.find("the run failed") != std::string::npos);
}

namespace {

// A free 10 cm cube of 4³ hexahedra about the origin, weightless and undamped, with the given
// integrator, step and "velocities" entries; 5 frames.
std::string spin_scene(const std::string& integrator, double step, double duration, const std::string& velocities) {
  return R"({"materials": {"rubber": {"young": 1e6, "density": 1000}},
  "meshes": [{"type": "hex_grid", "cells": [4, 4, 4], "size": [0.1, 0.1, 0.1], "origin": [-0.05, -0.05, -0.05], "material": "rubber"}],
  "gravity": [0, 0, 0], "damping": {"model": "none"},
  "integrator": {"type": ")" + integrator + R"(", "step": )" + std::to_string(step) + R"(},
  "duration": )" + std::to_string(duration) + R"(, "velocities": )" + velocities + R"(,
  "output": {"frames": 5, "vtu": false, "picture": {"enabled": false}}})";
}

RunSummary run_text(const std::string& text, const std::string& name, std::vector<std::string>& header,
                    std::vector<std::vector<double>>& rows) {
  const fs::path scene = scratch(name + ".json");
  write(scene, text);
  RunOptions opt;
  opt.quiet = true;
  opt.out = scratch(name);
  const RunSummary s = run(load_scene(scene.string()), opt);
  rows = read_csv(s.csv, header);
  return s;
}

double column(const std::vector<std::string>& header, const std::vector<double>& row, const std::string& name) {
  const auto it = std::find(header.begin(), header.end(), name);
  REQUIRE(it != header.end());
  return row[static_cast<std::size_t>(it - header.begin())];
}

}  // namespace

TEST_CASE("scene velocities: a uniform drift and a rigid spin, fixed axes left at rest") {
  std::vector<std::string> header;
  std::vector<std::vector<double>> rows;
  // uniform: the kinetic energy is ½ M v² with M = ρV = 1 kg, whatever the lumping
  run_text(spin_scene("semi-implicit", 1e-5, 1e-4, R"([{"where": {"type": "all"}, "linear": [0.3, 0.4, 0]}])"), "drift",
           header, rows);
  CHECK(column(header, rows[0], "kinetic_energy") == doctest::Approx(0.5 * 1.0 * 0.25).epsilon(1e-12));
  // a spin about z through the centre on the lower half only: ½ Σ m ω² (x² + y²) over the
  // particles with z <= 0, each of mass ρ a³/8 per incident cell (a = 2.5 cm)
  run_text(spin_scene("semi-implicit", 1e-5, 1e-4,
                      R"([{"where": {"type": "box", "min": [-1, -1, -1], "max": [1, 1, 0]}, "angular": [0, 0, 10]}])"),
           "spin_half", header, rows);
  const double a = 0.025, m_cell = 1000 * a * a * a / 8;
  double expected = 0;
  for (int i = 0; i <= 4; ++i)
    for (int j = 0; j <= 4; ++j)
      for (int k = 0; k <= 2; ++k) {
        const auto cells = [](int q) { return (q == 0 || q == 4) ? 1 : 2; };
        const double m = m_cell * cells(i) * cells(j) * cells(k);
        const double x = -0.05 + a * i, y = -0.05 + a * j;
        expected += 0.5 * m * 100 * (x * x + y * y);
      }
  CHECK(column(header, rows[0], "kinetic_energy") == doctest::Approx(expected).epsilon(1e-12));
  // an empty selection is named
  expect_run_error<SceneError>(spin_scene("implicit", 1e-3, 1e-2, R"([{"where": {"type": "box", "min": [5, 5, 5], "max": [6, 6, 6]}}])"),
                   "velocities[0].where");
}

TEST_CASE("a spinning cube: the linearly implicit step's energy rise is reported, the midpoint rule creates none") {
  std::vector<std::string> header;
  std::vector<std::vector<double>> rows;
  const std::string spin100 = R"([{"where": {"type": "all"}, "angular": [0, 0, 100]}])";
  const RunSummary fast = run_text(spin_scene("implicit", 0.01, 0.05, spin100), "spin100", header, rows);
  CHECK(fast.energy_rises >= 1);
  CHECK(fast.first_energy_rise.find("step 1 ") != std::string::npos);
  CHECK(column(header, rows.back(), "energy_rises") == static_cast<double>(fast.energy_rises));
  CHECK(column(header, rows[1], "dissipated") < 0);  // frame 1, after step 1: energy was created
  // the ratio column saw it at the step: kinetic + elastic far above what the start supplied
  CHECK(column(header, rows.back(), "energy_ratio_max") > 2.0);
  const auto angular = [&](const std::vector<double>& r) {
    return Eigen::Vector3d(column(header, r, "angular_momentum_x"), column(header, r, "angular_momentum_y"),
                           column(header, r, "angular_momentum_z"));
  };
  const auto linear = [&](const std::vector<double>& r) {
    return Eigen::Vector3d(column(header, r, "momentum_x"), column(header, r, "momentum_y"), column(header, r, "momentum_z"));
  };
  // ½ Σ m ω² r² = 9.375 J at 100 rad/s: L = 2 E / ω about the spin axis, and the implicit step loses it
  CHECK(angular(rows.front()).z() == doctest::Approx(2 * column(header, rows.front(), "kinetic_energy") / 100).epsilon(1e-9));
  CHECK(angular(rows.back()).z() < 0.9 * angular(rows.front()).z());
  const std::string spin10 = R"([{"where": {"type": "all"}, "angular": [0, 0, 10]}])";
  const RunSummary calm = run_text(spin_scene("midpoint", 0.01, 0.2, spin10), "spin10", header, rows);
  CHECK(calm.energy_rises == 0);
  CHECK(calm.substepped == 0);
  // the midpoint rule keeps both momenta, and the energy it was given
  CHECK((angular(rows.back()) - angular(rows.front())).norm() <= 1e-10 * angular(rows.front()).norm());
  CHECK(linear(rows.back()).norm() <= 1e-12);
  CHECK(column(header, rows.back(), "energy_ratio_max") == doctest::Approx(1.0).epsilon(1e-9));
  // a radian per step: the midpoint rule's Newton needs sub-steps, the summary counts them, no energy is made
  const RunSummary sub = run_text(spin_scene("midpoint", 0.01, 0.05, spin100), "spin100_midpoint", header, rows);
  CHECK(sub.substepped > 0);
  CHECK(sub.most_substeps > 1);
  CHECK(sub.energy_rises == 0);
  CHECK(std::abs(column(header, rows.back(), "dissipated")) <= 1e-9 * column(header, rows.front(), "total_energy"));
  const double e0 = column(header, rows.front(), "total_energy");
  CHECK(std::abs(column(header, rows.back(), "dissipated")) <= 1e-9 * e0);
}

TEST_CASE("inverted elements: counted per frame with the first reported, or the run stopped at the first") {
  // a 2x2x6 column of 5 cm cubes on the ground, its lower half 10^6 times softer than the top
  const std::string soft_column = R"({"materials": {"soft": {"young": 1e3, "density": 1000}, "stiff": {"young": 1e9, "density": 1000}},
  "meshes": [{"type": "hex_grid", "cells": [2, 2, 6], "size": [0.1, 0.1, 0.3], "material": "stiff",
              "regions": [{"where": {"type": "box", "min": [-1, -1, -1], "max": [1, 1, 0.15]}, "material": "soft"}]}],
  "fixed": [{"where": {"type": "box", "min": [-1, -1, -1], "max": [1, 1, 0.001]}}],
  "integrator": {"type": "implicit", "step": 0.001, "max_iterations": 10000)";
  const std::string rest = R"(}, "duration": 0.5, "output": {"frames": 10, "vtu": false, "picture": {"enabled": false}}})";
  std::vector<std::string> header;
  std::vector<std::vector<double>> rows;
  const RunSummary s = run_text(soft_column + rest, "column", header, rows);
  double most = 0;
  for (const auto& r : rows) most = std::max(most, column(header, r, "inverted"));
  MESSAGE("soft/stiff column: at most " << most << " of 24 hexahedra inverted in a frame; " << s.first_inversion);
  CHECK(most > 0);
  CHECK(static_cast<double>(s.inverted_max) == most);
  CHECK(s.first_inversion.find(" (meshes[0] cell ") != std::string::npos);
  CHECK(column(header, rows.front(), "inverted") == 0.0);
  const fs::path scene = scratch("column_stop.json");
  write(scene, soft_column + R"(, "stop_on_inversion": true)" + rest);
  RunOptions opt;
  opt.quiet = true;
  opt.out = scratch("column_stop");
  CHECK_THROWS_WITH(run(load_scene(scene.string()), opt), doctest::Contains("inverted at step"));
}

TEST_CASE("materials' volume_stiffness keeps the soft region of the column from inverting") {
  // the column above, the soft material with a bulk stiffness 100 times its Young's modulus
  const std::string volume_column = R"({"materials": {"soft": {"young": 1e3, "density": 1000, "volume_stiffness": 1e5},
  "stiff": {"young": 1e9, "density": 1000}},
  "meshes": [{"type": "hex_grid", "cells": [2, 2, 6], "size": [0.1, 0.1, 0.3], "material": "stiff",
              "regions": [{"where": {"type": "box", "min": [-1, -1, -1], "max": [1, 1, 0.15]}, "material": "soft"}]}],
  "fixed": [{"where": {"type": "box", "min": [-1, -1, -1], "max": [1, 1, 0.001]}}],
  "integrator": {"type": "implicit", "step": 0.001, "max_iterations": 10000}, "duration": 0.5)";
  const std::string rest = R"(, "output": {"frames": 10, "vtu": false, "picture": {"enabled": false}}})";
  std::vector<std::string> header;
  std::vector<std::vector<double>> rows;
  const RunSummary s = run_text(volume_column + rest, "column_volume", header, rows);
  CHECK(s.inverted_max == 0);
  for (const auto& r : rows) CHECK(column(header, r, "inverted") == 0.0);
  // its energy is elastic energy: the columns still add up (total = kinetic + elastic + gravity)
  const auto& last = rows.back();
  CHECK(column(header, last, "total_energy") ==
        doctest::Approx(column(header, last, "kinetic_energy") + column(header, last, "elastic_energy") +
                        column(header, last, "gravity_energy")).epsilon(1e-12));
  // a cut through the soft region: the term follows it (each stencil on its element's particles
  // after the cut, tested in tests/physics/test_volume_term.cpp), and the column still stands
  std::vector<std::vector<double>> cut_rows;
  // and then a pierce that removes the soft layer at the bottom: its stencils are retired with it
  const RunSummary cut = run_text(volume_column + R"(, "cuts": [{"type": "plane", "time": 0.1, "point": [0, 0, 0.1], "normal": [0, 0, 1]},
    {"type": "pierce", "time": 0.2, "remove": true, "where": {"type": "box", "min": [-1, -1, -1], "max": [1, 1, 0.05]}}])" + rest,
                                  "column_volume_cut", header, cut_rows);
  CHECK(cut.cuts == 2);
  CHECK(cut.inverted_max == 0);
  CHECK(column(header, cut_rows.back(), "elements") == 20.0);  // 24 less the 4 pierced away
  // with refinement: the children get their own stencils (tests/apps/test_refine_keys.cpp
  // checks the volume kept), and the column still stands
  std::vector<std::vector<double>> refined_rows;
  const RunSummary refined = run_text(volume_column + R"(, "refinement": {"criteria": [{"type": "diagonal_strain", "threshold": 1.2}], "max_level": 2})" + rest,
                                      "column_volume_refined", header, refined_rows);
  CHECK(refined.refined > 0);
  CHECK(refined.inverted_max == 0);
  const auto& end = refined_rows.back();
  CHECK(column(header, end, "total_energy") ==
        doctest::Approx(column(header, end, "kinetic_energy") + column(header, end, "elastic_energy") +
                        column(header, end, "gravity_energy")).epsilon(1e-12));
  expect_run_error<SceneError>(R"({"materials": {"m": {"young": 1e6, "density": 1000, "volume_stiffness": -1}},
                                   "meshes": [{"type": "hex_grid", "cells": [1, 1, 1], "size": [1, 1, 1], "material": "m"}]})",
                               "materials.m.volume_stiffness");
}

TEST_CASE("the clamp policy for elongated cells is announced with the number of cells it altered") {
  const auto beam = [](const std::string& policy) {
    return R"({"materials": {"m": {"young": 100e6, "density": 1000)" + policy + R"(}},
  "meshes": [{"type": "hex_grid", "cells": [4, 2, 2], "size": [1.0, 0.1, 0.1], "material": "m"}],
  "fixed": [{"where": {"type": "box", "min": [-1, -1, -1], "max": [0.001, 1, 1]}}],
  "duration": 0.002, "output": {"frames": 1, "vtu": false, "picture": {"enabled": false}}})";
  };
  std::vector<std::string> header;
  std::vector<std::vector<double>> rows;
  const RunSummary s = run_text(beam(R"(, "elongated": "clamp")"), "clamped", header, rows);
  CHECK(s.clamped_cells == 16);  // 5:1 boxes: every cell
  const RunSummary cubes = run_text(R"({"materials": {"m": {"young": 100e6, "density": 1000, "elongated": "clamp"}},
  "meshes": [{"type": "hex_grid", "cells": [10, 1, 1], "size": [1.0, 0.1, 0.1], "material": "m"}],
  "duration": 0.002, "output": {"frames": 1, "vtu": false, "picture": {"enabled": false}}})", "cubes", header, rows);
  CHECK(cubes.clamped_cells == 0);
  expect_run_error<sewn::physics::InputError>(beam(""), "too elongated");
  // split: every 5:1 box cut into 5 near-cubes, no stiffness altered, the run goes on
  const RunSummary split = run_text(beam(R"(, "elongated": "split")"), "split", header, rows);
  CHECK(split.split_cells == 16);
  CHECK(split.clamped_cells == 0);
  CHECK(column(header, rows.back(), "elements") == 80.0);
  CHECK(column(header, rows.back(), "particles") == 21.0 * 3 * 3);
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
  // Runs scene text; the last row of its frames.csv, by column name.
  struct LastFrame {
    RunSummary sum;
    std::vector<std::string> header;
    std::vector<std::vector<double>> rows;
    [[nodiscard]] double operator[](const std::string& name) const {
      const auto c = static_cast<std::size_t>(std::find(header.begin(), header.end(), name) - header.begin());
      REQUIRE(c < header.size());
      return rows.back()[c];
    }
  };
  auto run_text = [](const std::string& text, const std::string& name) {
    const fs::path file = scratch(name + ".json");
    write(file, text);
    RunOptions opt;
    opt.quiet = true;
    opt.out = scratch(name + "_out");
    LastFrame f;
    f.sum = run(load_scene(file.string()), opt);
    f.rows = read_csv(f.sum.csv, f.header);
    return f;
  };
  SUBCASE("runs, with no spring left and elastic energy from the tetrahedra") {
    const LastFrame f = run_text(scene("tet_grid", rayleigh, ""), "solid");
    CHECK(f.sum.steps == 20);
    CHECK(f["springs"] == 0.0);
    CHECK(f["elements"] == 24.0);
    CHECK(f["elastic_energy"] > 0.0);
    CHECK(std::isfinite(f["kinetic_energy"]));
  }
  SUBCASE("hexahedra") {
    expect_run_error<SceneError>(scene("hex_grid", rayleigh, ""), "needs tetrahedra only");
  }
  SUBCASE("shell: membranes and patch bending on a triangle mesh; a volume mesh is refused") {
    std::string text = scene("tri_grid", rayleigh, "");
    text.replace(text.find(R"("solid", "law": "stvk")"), 22, R"("shell")");
    text.replace(text.find(R"("cells": [4, 1, 1], "size": [0.4, 0.1, 0.1])"), 43, R"("cells": [4, 1], "size": [0.4, 0.1])");
    const LastFrame f = run_text(text, "shell");
    CHECK(f["springs"] == 0.0);
    CHECK(f["elements"] == 8.0);
    CHECK(f["elastic_energy"] > 0.0);
    std::string hex = scene("tet_grid", rayleigh, "");
    hex.replace(hex.find(R"("solid", "law": "stvk")"), 22, R"("shell")");
    expect_run_error<SceneError>(hex, "needs triangles only");
    // Morley bending's edge angles are integrated by Newton alone
    std::string implicit = text;
    implicit.replace(implicit.find(R"("type": "shell")"), 15, R"("type": "shell", "bending": "morley")");
    implicit.replace(implicit.find(R"("type": "newton")"), 16, R"("type": "implicit")");
    expect_run_error<SceneError>(implicit, "model.bending: \"morley\" bending gives every shell edge an angle DOF");
  }
  SUBCASE("per-spring damping") {
    expect_run_error<SceneError>(scene("tet_grid", R"({"model": "viscous"})", ""), "per-spring damping");
  }
  SUBCASE("cuts: the tetrahedra and shells follow a plane cut and a piercing; cut rods are refused") {
    const LastFrame f = run_text(scene("tet_grid", rayleigh, R"(, "cuts": [{"type": "plane", "time": 0.05, "point": [0.2, 0, 0], "normal": [1, 0, 0]}])"),
                                 "solid_cut");
    CHECK(f.sum.cuts == 1);
    CHECK(f["springs"] == 0.0);
    CHECK(f["particles"] == 24.0);  // the 2 × 2 section points at x = 0.2 duplicated
    CHECK(f["elements"] == 24.0);
    // the last cube's 6 tetrahedra pierced away: their Tets elements leave with them
    const LastFrame pierced = run_text(scene("tet_grid", rayleigh, R"(, "cuts": [{"type": "pierce", "time": 0.05, "remove": true,
                                           "where": {"type": "box", "min": [0.3, -1, -1], "max": [1, 1, 1]}}])"),
                                       "solid_pierce");
    CHECK(pierced.sum.cuts == 1);
    CHECK(pierced["elements"] == 18.0);
    CHECK(pierced["particles"] == 16.0);  // the 4 corner points at x = 0.4 went with them
    std::string shell = scene("tri_grid", rayleigh, R"(, "cuts": [{"type": "plane", "time": 0.05, "point": [0.2, 0, 0], "normal": [1, 0, 0]}])");
    shell.replace(shell.find(R"("cells": [4, 1, 1], "size": [0.4, 0.1, 0.1])"), 43, R"("cells": [4, 1], "size": [0.4, 0.1])");
    std::string morley_shell = shell;
    morley_shell.replace(morley_shell.find(R"("solid", "law": "stvk")"), 22, R"("shell", "bending": "morley")");
    expect_run_error<SceneError>(morley_shell, "model.bending: this scene cuts 8 shell triangles, which \"morley\" bending cannot follow yet");
    std::string patch_shell = shell;  // the default bending
    patch_shell.replace(patch_shell.find(R"("solid", "law": "stvk")"), 22, R"("shell")");
    expect_run_error<SceneError>(patch_shell, "model.bending: this scene cuts 8 shell triangles, which \"patch\" bending cannot follow yet");
    shell.replace(shell.find(R"("solid", "law": "stvk")"), 22, R"("shell", "bending": "hinge")");
    const LastFrame cut_shell = run_text(shell, "shell_cut");  // the membranes and hinges follow the cut
    CHECK(cut_shell.sum.cuts == 1);
    CHECK(cut_shell["particles"] == 12.0);  // the 2 points at x = 0.2 duplicated
    CHECK(cut_shell["elements"] == 8.0);
    const std::string rod = R"({"materials": {"m": {"young": 1e9, "density": 1000}},
      "meshes": [{"type": "polyline", "material": "m", "points": [[0,0,0],[0.1,0,0],[0.2,0,0]]}],
      "model": {"type": "mixed"}, "damping": )" + rayleigh + R"(, "integrator": {"type": "newton", "step": 0.005}, "duration": 0.1,
      "cuts": [{"type": "plane", "time": 0.05, "point": [0.1, 0, 0], "normal": [1, 0, 0]}]})";
    expect_run_error<SceneError>(rod, "cutting is supported on solid tetrahedra and shells only, and this scene has 2 rod segments");
  }
}

// OPENBLAS_VERBOSE=2 makes OpenBLAS print the kernels it loads ("Core: <name>"), once per process.
std::vector<std::string> openblas_cores(const std::string& printed) {
  std::vector<std::string> cores;
  std::istringstream in(printed);
  for (std::string line; std::getline(in, line);)
    if (line.rfind("Core: ", 0) == 0) cores.push_back(line.substr(6));
  return cores;
}

TEST_CASE("sewn run starts again with the CPU's OpenBLAS kernels where OpenBLAS fell back to its generic ones") {
  namespace solve = sewn::physics::solve;
  if (solve::openblas_kernels().empty()) return;  // built without OpenBLAS: nothing to choose
  // This process loaded the same OpenBLAS from the same environment: it says what the tool sees.
  const std::string wanted = solve::openblas_coretype_wanted();
  std::string err;
  REQUIRE(run_binary("run --until 0.01 --quiet --out " + scratch("kernels").string(), err, "OPENBLAS_VERBOSE=2") == 0);
  const std::vector<std::string> cores = openblas_cores(err);
  CAPTURE(err);
  if (wanted.empty()) {
    CHECK(cores.size() == 1);
  } else {
    REQUIRE(cores.size() == 2);
    CHECK(cores[0] == solve::openblas_kernels());
    CHECK(cores[1] == wanted);
  }
  // the user's choice stands: one process, the kernels asked for
  REQUIRE(run_binary("run --until 0.01 --quiet --out " + scratch("kernels").string(), err,
                     "OPENBLAS_VERBOSE=2 OPENBLAS_CORETYPE=Prescott") == 0);
  REQUIRE(openblas_cores(err).size() == 1);
  CHECK(openblas_cores(err)[0] == "Prescott");
  // other commands do not start twice
  REQUIRE(run_binary("--help", err, "OPENBLAS_VERBOSE=2") == 0);
  CHECK(openblas_cores(err).size() == 1);
}

TEST_CASE("a hypre-pcg run whose MPI solvers module cannot be loaded fails naming the path tried") {
  if (!sewn::physics::solve::available(sewn::physics::solve::Backend::hypre_pcg)) return;  // not built
  const fs::path scene = scratch("mpi_module.json");
  write(scene, R"({"materials": {"m": {"young": 1e6, "density": 1000}},
    "meshes": [{"type": "hex_grid", "material": "m", "cells": [2, 1, 1], "size": [0.2, 0.1, 0.1]}],
    "fixed": [{"where": {"type": "box", "min": [-1, -1, -1], "max": [0.001, 1, 1]}}],
    "integrator": {"type": "implicit", "step": 0.001, "solver": "hypre-pcg"}, "duration": 0.002})");
  std::string err;
  const std::string args = "run " + scene.string() + " --quiet --out " + scratch("mpi_module").string();
  CHECK(run_binary(args, err, "SEWN_MPI_SOLVERS=/nonexistent/libsewn_mpi_solvers.so") == 1);
  CAPTURE(err);
  CHECK(err.find("could not be loaded") != std::string::npos);
  CHECK(err.find("/nonexistent/libsewn_mpi_solvers.so") != std::string::npos);
  CHECK(run_binary(args, err) == 0);  // where the build put it
}

}  // namespace test_run
