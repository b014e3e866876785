// Hard cases of the Newton path (rods, shells, elastic solids; issue 15/16's sweep, bench/hard/notes.md):
// what used to give a silent wrong answer now warns or refuses, naming what and where.
#include <doctest/doctest.h>

#include <algorithm>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "sewn/apps/runner.hpp"
#include "sewn/apps/scene.hpp"
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
  RunOptions opt;
  opt.quiet = true;
  opt.out = sewn::test::scratch("hard_newton/beam");
  const RunSummary s = run(load_scene(scene.string()), opt);
  // gravity energy M g z̄, measured from z = 0; the beam's centroid starts at z = 0.05 m (M = 10 kg)
  std::ifstream csv(s.csv);
  std::string line;
  std::getline(csv, line);
  const auto header = split(line);
  const auto at = static_cast<std::size_t>(std::find(header.begin(), header.end(), "gravity_energy") - header.begin());
  std::vector<std::string> last;
  while (std::getline(csv, line))
    if (!line.empty()) last = split(line);
  REQUIRE(at < last.size());
  mean_sag = 0.05 - std::stod(last[at]) / (10.0 * 9.81);
  return s;
}

}  // namespace

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

}  // namespace test_hard_newton
