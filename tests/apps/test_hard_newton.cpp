// Hard cases of the Newton path (rods, shells, elastic solids; issue 15/16's sweep, bench/hard/notes.md):
// what used to give a silent wrong answer now warns or refuses, naming what and where.
#include <doctest/doctest.h>

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "sewn/apps/runner.hpp"
#include "sewn/apps/scene.hpp"
#include "sewn/physics/errors.hpp"
#include "scratch.hpp"

namespace test_hard_newton {

using namespace sewn::app;

namespace {

std::vector<std::string> split(const std::string& line) {
  std::vector<std::string> out;
  std::stringstream in(line);
  for (std::string field; std::getline(in, field, ',');) out.push_back(field);
  return out;
}

// Runs the scene file quietly, its output in scratch folder `out`.
RunSummary run_quietly(const std::filesystem::path& scene, const std::string& out) {
  RunOptions opt;
  opt.quiet = true;
  opt.out = sewn::test::scratch("hard_newton/" + out);
  return run(load_scene(scene.string()), opt);
}

// What a run of the scene that refuses it says (a SceneError or a physics::InputError), "" if it ran.
std::string refusal(const std::filesystem::path& scene, const std::string& out) {
  try {
    (void)run_quietly(scene, out);
  } catch (const SceneError& e) {
    return e.what();
  } catch (const sewn::physics::InputError& e) {
    return e.what();
  }
  return "";
}

// The value of `column` in the last row of a frames.csv.
double last_value(const std::filesystem::path& csv_path, const std::string& column) {
  std::ifstream csv(csv_path);
  std::string line;
  std::getline(csv, line);
  const auto header = split(line);
  const auto at = static_cast<std::size_t>(std::find(header.begin(), header.end(), column) - header.begin());
  std::vector<std::string> last;
  while (std::getline(csv, line))
    if (!line.empty()) last = split(line);
  REQUIRE(at < last.size());
  return std::stod(last[at]);
}

// scenes/solid_cantilever.json's beam brought to rest (h = 0.1 s, strong Rayleigh damping) at
// Poisson's ratio `nu`; returns the run's summary and the mean sag (m) from its gravity energy.
RunSummary cantilever_at_rest(double nu, double& mean_sag) {
  const std::string text = R"({"materials": {"beam": {"young": 1e8, "poisson": )" + std::to_string(nu) +
                           R"(, "density": 1000}},
    "meshes": [{"type": "tet_grid", "material": "beam", "cells": [20, 2, 2], "size": [1.0, 0.1, 0.1]}],
    "fixed": [{"where": {"type": "box", "min": [-1, -1, -1], "max": [0.0001, 1, 1]}}],
    "gravity": [0, 0, -9.81], "model": {"type": "solid"}, "damping": {"model": "rayleigh", "alpha": 50},
    "integrator": {"type": "newton", "step": 0.1}, "duration": 3,
    "output": {"frames": 1, "vtu": false, "picture": {"enabled": false}}})";
  const auto scene = sewn::test::scratch_file("hard_newton/beam.json", text);
  const RunSummary s = run_quietly(scene, "beam");
  // gravity energy M g z̄, measured from z = 0; the beam's centroid starts at z = 0.05 m (M = 10 kg)
  mean_sag = 0.05 - last_value(s.csv, "gravity_energy") / (10.0 * 9.81);
  return s;
}

// A MEDIT file of a plate 0.2 x 0.05 m in z = 0 (8 x 4 cells of 2 triangles, tag 1) with a fin
// standing on the line x = 0.1 along its first `fin_cells` cells in y (tag 2); no fin if 0.
std::string plate_with_fin(int fin_cells) {
  const int nx = 8, ny = 4;
  std::ostringstream pts, tris;
  int n_pts = 0, n_tris = 0;
  const auto point = [&](double x, double y, double z) {
    pts << x << " " << y << " " << z << " 0\n";
    return ++n_pts;  // MEDIT numbers from 1
  };
  const auto tri = [&](int a, int b, int c, int tag) {
    tris << a << " " << b << " " << c << " " << tag << "\n";
    ++n_tris;
  };
  std::vector<int> id;
  for (int j = 0; j <= ny; ++j)
    for (int i = 0; i <= nx; ++i) id.push_back(point(0.2 * i / nx, 0.05 * j / ny, 0.0));
  const auto at = [&](int i, int j) { return id[static_cast<std::size_t>(j * (nx + 1) + i)]; };
  for (int j = 0; j < ny; ++j)
    for (int i = 0; i < nx; ++i) {
      tri(at(i, j), at(i + 1, j), at(i + 1, j + 1), 1);
      tri(at(i, j), at(i + 1, j + 1), at(i, j + 1), 1);
    }
  std::vector<int> top;
  for (int j = 0; fin_cells > 0 && j <= fin_cells; ++j) top.push_back(point(0.1, 0.05 * j / ny, 0.01));
  for (int j = 0; j < fin_cells; ++j) {
    const auto k = static_cast<std::size_t>(j);
    tri(at(4, j), at(4, j + 1), top[k + 1], 2);
    tri(at(4, j), top[k + 1], top[k], 2);
  }
  return "MeshVersionFormatted 2\nDimension 3\nVertices\n" + std::to_string(n_pts) + "\n" + pts.str() + "Triangles\n" +
         std::to_string(n_tris) + "\n" + tris.str() + "End\n";
}

// The plate clamped at x <= 25 mm (two rows of nodes: patch bending's clamp), brought to rest
// under gravity with connections on; the fin nearly massless (its own material) so that the
// sag compares with the bare plate's. Returns the summary and the gravity energy at rest (J).
RunSummary plate_at_rest(int fin_cells, double& gravity_energy) {
  sewn::test::scratch_file("hard_newton/plate.mesh", plate_with_fin(fin_cells));
  const std::string fin = fin_cells > 0 ? R"(, "regions": [{"where": {"type": "tag", "tag": 2}, "material": "light"}])" : "";
  const auto scene = sewn::test::scratch_file("hard_newton/plate.json", R"({
    "materials": {"m": {"young": 1e9, "poisson": 0.3, "density": 1000, "thickness": 0.002},
                  "light": {"young": 1e9, "poisson": 0.3, "density": 0.01, "thickness": 0.002}},
    "meshes": [{"type": "file", "path": "plate.mesh", "material": "m")" + fin + R"(}],
    "fixed": [{"where": {"type": "box", "min": [-1, -1, -1], "max": [0.0251, 1, 1]}}],
    "gravity": [0, 0, -9.81], "damping": {"model": "rayleigh", "alpha": 20},
    "model": {"type": "mixed", "bending": "patch", "connections": {}},
    "integrator": {"type": "newton", "step": 0.01}, "duration": 2,
    "output": {"frames": 1, "vtu": false, "picture": {"enabled": false}}})");
  const RunSummary s = run_quietly(scene, "plate");
  gravity_energy = last_value(s.csv, "gravity_energy");
  return s;
}

}  // namespace

TEST_CASE("a fin along part of a plate's line hinges the plate there, and the run says so") {
  double bare = 0, part = 0, whole = 0;
  const RunSummary b = plate_at_rest(0, bare);
  const RunSummary p = plate_at_rest(2, part);
  const RunSummary w = plate_at_rest(4, whole);
  // half the line hinged: 9 % more sag; the whole line parts the plate, and the connections
  // join the pieces (a joint as stiff as one cell: a little stiffer than the bare plate)
  CHECK(part / bare > 1.05);
  CHECK(whole / bare == doctest::Approx(1.0).epsilon(0.05));
  CHECK(b.model_warnings.empty());
  CHECK(w.model_warnings.empty());
  REQUIRE(p.model_warnings.size() == 1);
  CHECK_MESSAGE(p.model_warnings[0].find("2 edge(s) shared by 3 or more shell triangles of one sheet (first: the edge "
                                          "(0.1, 0, 0) to (0.1, 0.0125, 0) of meshes[0] cell 6") == 0,
                p.model_warnings[0]);
}

TEST_CASE("nearly incompressible linear tetrahedra lock, and the run says so") {
  double soft = 0, locked = 0;
  const RunSummary s3 = cantilever_at_rest(0.3, soft);
  const RunSummary s5 = cantilever_at_rest(0.4999, locked);
  // The continuum's mean sag, qL⁴/(20EI) = 5.9 mm, barely depends on ν; the mesh's drops 20x.
  CHECK(soft == doctest::Approx(3.02e-3).epsilon(0.02));
  CHECK(locked == doctest::Approx(0.13e-3).epsilon(0.1));
  CHECK(s3.model_warnings.empty());
  REQUIRE(s5.model_warnings.size() == 1);
  const std::string& w = s5.model_warnings[0];
  CHECK_MESSAGE(w.find("materials.beam.poisson: nu = 0.4999 on 480 solid tetrahedra") == 0, w);
  CHECK_MESSAGE(w.find("lock") != std::string::npos, w);
}

TEST_CASE("a rod on a plate's node that is not the plate's own point is said to be unjoined") {
  // The rod's top point is a plate node's place, but in another mesh (or a duplicate node of a
  // file): the two share no node, and the rod fell off the plate with nothing said.
  const auto scene = [](const std::string& rod) {
    return sewn::test::scratch_file("hard_newton/rod_on_plate.json", R"({
      "materials": {"m": {"young": 1e9, "poisson": 0.3, "density": 1000, "thickness": 0.002}},
      "meshes": [{"type": "tri_grid", "cells": [4, 2], "size": [0.1, 0.05], "material": "m"})" + rod + R"(],
      "fixed": [{"where": {"type": "box", "min": [-1, -1, -1], "max": [0.0251, 1, 1]}}],
      "model": {"type": "mixed"}, "damping": {"model": "rayleigh", "alpha": 20},
      "integrator": {"type": "newton", "step": 0.01, "solver": "ldlt"}, "duration": 0.01,
      "output": {"frames": 1, "vtu": false, "picture": {"enabled": false}}})");
  };
  const RunSummary alone = run_quietly(scene(""), "rod_on_plate");
  CHECK(alone.model_warnings.empty());
  const RunSummary both =
      run_quietly(scene(R"(, {"type": "polyline", "points": [[0.1, 0.025, 0], [0.1, 0.025, -0.02]], "material": "m"})"), "rod_on_plate");
  REQUIRE(both.model_warnings.size() == 1);
  CHECK_MESSAGE(both.model_warnings[0].find("1 pair(s) of distinct mesh points coincide (first: at (0.1, 0.025, 0), of "
                                             "meshes[0] cell 6 (shell) and meshes[1] cell 0 (rod))") == 0,
                both.model_warnings[0]);
  CHECK(both.connections.find("none") != std::string::npos);  // what the run simulated: no joint
}

TEST_CASE("a shell triangle given reversed is refused naming its cell in the file") {
  // two triangles of a square, the second listed clockwise: the diagonal runs 3 -> 1 in both
  sewn::test::scratch_file("hard_newton/square.mesh",
                           "MeshVersionFormatted 2\nDimension 3\nVertices\n4\n0 0 0 0\n1 0 0 0\n1 1 0 0\n0 1 0 0\n"
                           "Triangles\n2\n1 2 3 1\n1 4 3 1\nEnd\n");
  for (const char* bending : {"hinge", "patch", "morley"}) {
    const auto scene = sewn::test::scratch_file("hard_newton/square.json", std::string(R"({
      "materials": {"m": {"young": 1e9, "poisson": 0.3, "density": 1000, "thickness": 0.002}},
      "meshes": [{"type": "file", "path": "square.mesh", "material": "m"}],
      "model": {"type": "shell", "bending": ")") + bending + R"("}, "damping": {"model": "none"},
      "integrator": {"type": "newton", "step": 0.01}, "duration": 0.01,
      "output": {"frames": 1, "vtu": false, "picture": {"enabled": false}}})");
    const std::string told = refusal(scene, "square");
    // it used to say "meshes: shell triangles: triangles 0 and 1 ...", in the model's own numbering
    CHECK_MESSAGE(told.find("meshes[0]: cell 1 of " + sewn::test::scratch("hard_newton/square.mesh").string() +
                            " (triangle) runs its edge from corner 2 to corner 0 the same way as the shell triangle "
                            "across it: the two are oriented inconsistently") != std::string::npos,
                  bending << ": " << told);
  }
}

TEST_CASE("a body meshed into an obstacle is said to start inside it") {
  // a cube 0.1 m on a side with its lower half behind a ground plane at z = 0.05: the penalty's
  // energy launched it (centroid 1.02 m up after 0.5 s) with nothing said
  const auto summary = [](double ground) {
    const auto scene = sewn::test::scratch_file("hard_newton/ground.json", R"({
      "materials": {"m": {"young": 1e6, "poisson": 0.3, "density": 1000}},
      "meshes": [{"type": "tet_grid", "material": "m", "cells": [3, 3, 3], "size": [0.1, 0.1, 0.1]}],
      "obstacles": [{"type": "plane", "point": [0, 0, )" + std::to_string(ground) + R"(], "normal": [0, 0, 1]}],
      "model": {"type": "solid"}, "damping": {"model": "rayleigh", "alpha": 5},
      "integrator": {"type": "newton", "step": 0.01}, "duration": 0.01,
      "output": {"frames": 1, "vtu": false, "picture": {"enabled": false}}})");
    return run_quietly(scene, "ground");
  };
  CHECK(summary(0.0).model_warnings.empty());  // resting on it: no particle inside
  const RunSummary inside = summary(0.05);
  REQUIRE(inside.model_warnings.size() == 1);
  // the grid's layers z = 0 and 0.0333 are inside: 2 x 16 particles, the deepest 0.05 m; each
  // layer holds 16 x ½ k d² with k = 1e5 N/m: 2000 + 222.2 J
  CHECK_MESSAGE(inside.model_warnings[0].find("obstacles[0] (plane): 32 particle(s) start inside it, the deepest 0.05 m "
                                               "(particle 0 at (0, 0, 0)); its penalty holds 2222.22 J") == 0,
                inside.model_warnings[0]);
}

TEST_CASE("an explicit connection far from every mesh point says how far, and the tolerance, in metres") {
  const auto scene = sewn::test::scratch_file("hard_newton/far_joint.json", R"({
    "materials": {"m": {"young": 1e9, "poisson": 0.3, "density": 1000, "thickness": 0.002}},
    "meshes": [{"type": "tri_grid", "cells": [4, 2], "size": [0.1, 0.05], "material": "m"}],
    "model": {"type": "mixed", "connections": {"explicit": [{"kind": "curve", "at": [0.3, 0.025, 0]}]}},
    "damping": {"model": "none"}, "integrator": {"type": "newton", "step": 0.01}, "duration": 0.01,
    "output": {"frames": 1, "vtu": false, "picture": {"enabled": false}}})");
  const std::string told = refusal(scene, "far_joint");
  // the tolerance, 1e-6 of the plate's diagonal (0.112 m), used to print as 0.000000 m
  CHECK_MESSAGE(told.find("model.connections.explicit[0].at: no mesh point is there: the nearest is meshes[0] point 9 at "
                          "[0.1, 0.025, 0], 0.2 m away (tolerance 1.11803e-07 m)") != std::string::npos,
                told);
}

TEST_CASE("a Newton step that stops right after a deep line-search cut is flagged as doubtful") {
  // A rod pinned at one end and released horizontal, 20 s: at h = 10 s and 1e-3 m/s Newton's
  // step test passed one iteration after the line search had cut the step to 3e-5, with the rod
  // 9 % of the way down (the settled fall is 0.1 m at h = 10 ms); it said nothing.
  const auto pendulum = [](double h, double& fall) {
    char integrator[160];
    std::snprintf(integrator, sizeof integrator, R"("type": "newton", "step": %g, "solver": "ldlt", "newton_tolerance": 1e-3)", h);
    const auto scene = sewn::test::scratch_file("hard_newton/pendulum.json", std::string(R"({
      "materials": {"w": {"young": 2e8, "poisson": 0.35, "density": 1200}},
      "meshes": [{"type": "polyline", "points": [[0, 0, 0], [0.1, 0, 0], [0.2, 0, 0]], "material": "w"}],
      "fixed": [{"where": {"type": "box", "min": [-1, -1, -1], "max": [0.0001, 1, 1]}}],
      "gravity": [0, 0, -9.81], "damping": {"model": "rayleigh", "alpha": 0.5},
      "model": {"type": "mixed", "groups": [{"tag": 0, "as": "rod", "radius": 0.003}]},
      "integrator": {)") + integrator + R"(}, "duration": 20,
      "output": {"frames": 1, "vtu": false, "picture": {"enabled": false}}})");
    const RunSummary s = run_quietly(scene, "pendulum");
    const double mass = 1200 * 3.141592653589793 * 0.003 * 0.003 * 0.2;
    fall = -last_value(s.csv, "gravity_energy") / (mass * 9.81);
    return s;
  };
  double settled = 0, crawled = 0;
  const RunSummary fine = pendulum(0.01, settled);
  const RunSummary coarse = pendulum(10, crawled);
  CHECK(settled == doctest::Approx(0.1).epsilon(1e-3));  // hanging straight down: its centre 0.1 m below the pin
  CHECK(crawled < 0.2 * settled);                       // what the loose test let through
  CHECK(fine.newton_short_stops == 0);
  CHECK(coarse.newton_short_stops >= 1);
  CHECK_MESSAGE(coarse.first_newton_short_stop.find("the Newton step at t = 0 s stopped 2 iteration(s) in, right after its "
                                                     "line search had cut the step to") == 0,
                coarse.first_newton_short_stop);
}

}  // namespace test_hard_newton
