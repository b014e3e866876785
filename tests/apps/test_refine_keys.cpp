// The scene key `refinement`: defaults, bad values refused with the key path, and runs where
// the beam of the 2014 paper's Table 1 is pre-refined and refined adaptively.
#include <doctest/doctest.h>

#include <filesystem>
#include <fstream>
#include <string>

#include "sewn/apps/runner.hpp"
#include "sewn/apps/scene.hpp"

using namespace sewn::app;
using nlohmann::json;

namespace refine_keys_test {

json beam_scene() {
  return json::parse(R"({
    "materials": {"paper": {"young": 1e5, "poisson": 0.3, "density": 100}},
    "meshes": [{"type": "hex_grid", "material": "paper", "cells": [2, 1, 1], "size": [2, 1, 1]}],
    "fixed": [{"where": {"type": "box", "min": [-1, -1, -1], "max": [0.001, 2, 2]}}],
    "integrator": {"step": 0.001},
    "duration": 0.3,
    "output": {"vtu": false, "csv": true, "picture": {"enabled": false}}
  })");
}

std::string refused(const json& j) {
  try {
    (void)parse_scene(j, "bad.json");
  } catch (const SceneError& e) {
    return e.path() + ": " + e.reason();
  }
  return "accepted";
}

std::string run_refused(const json& j) {
  try {
    RunOptions o;
    o.quiet = true;
    o.out = std::filesystem::temp_directory_path() / "sewn_refine_keys_refused";
    (void)run(parse_scene(j, "bad.json"), o);
  } catch (const SceneError& e) {
    return e.path() + ": " + e.reason();
  }
  return "ran";
}

// The value of column `name` in a frames.csv row.
double csv_value(const std::string& header, const std::string& row, const std::string& name) {
  std::size_t col = 0, at = 0;
  for (std::size_t p = 0; p < header.find(name); ++p) col += header[p] == ',';
  for (std::size_t c = 0; c < col; ++c) at = row.find(',', at) + 1;
  return std::stod(row.substr(at));
}



TEST_CASE("scene refinement: defaults, criteria and pre-refined regions") {
  CHECK_FALSE(parse_scene(beam_scene(), "s.json").refinement.enabled);
  json j = beam_scene();
  j["refinement"] = json::parse(R"({
    "criteria": [{"type": "diagonal_strain", "threshold": 1.2},
                 {"type": "region", "where": {"type": "sphere", "center": [0, 0, 0], "radius": 0.5}},
                 {"type": "point", "point": [1, 2, 3], "radius": 0.1}],
    "pre_refine": [{"where": {"type": "all"}}]
  })");
  const Scene s = parse_scene(j, "s.json");
  const RefinementSpec& r = s.refinement;
  CHECK(r.enabled);
  REQUIRE(r.criteria.size() == 3);
  CHECK(r.criteria[0].threshold == 1.2);
  CHECK(r.criteria[1].where.type == Selector::Type::sphere);
  CHECK(r.criteria[2].radius == 0.1);
  CHECK(r.max_level == 3);
  CHECK(r.pre_refine.at(0).levels == 1);
  CHECK_FALSE(r.coarsen);
  CHECK(r.calm_steps == 20);
  CHECK_FALSE(r.balance);
  CHECK(r.t_junctions == "reduction");
  CHECK(r.max_elements == doctest::Approx(8e9 / 4400));
}

TEST_CASE("scene refinement: bad values name their key") {
  auto with = [](const char* refinement) {
    json j = beam_scene();
    j["refinement"] = json::parse(refinement);
    return refused(j);
  };
  CHECK(with(R"({"criteria": [{"type": "diagonal_strain", "threshold": 0}]})").find("refinement.criteria[0].threshold") == 0);
  CHECK(with(R"({"criteria": [{"type": "diagonal_strain"}]})").find("refinement.criteria[0].threshold") == 0);
  CHECK(with(R"({"criteria": [{"type": "curvature"}]})").find("refinement.criteria[0].type") == 0);
  CHECK(with(R"({"max_level": 9})").find("refinement.max_level") == 0);
  CHECK(with(R"({"criteria": [{"type": "region", "where": {"type": "tag", "tag": 3}}]})") ==
        "refinement.criteria[0].where.type: refinement regions are geometric (all, box or sphere): refined elements carry no mesh tag or point list");
  CHECK(with(R"({"max_level": 2, "pre_refine": [{"where": {"type": "all"}, "levels": 2}]})") ==
        "refinement.pre_refine[0].levels: 2 refinements of the mesh's elements reach level 3, above refinement.max_level = 2");
  // pre-refinement counts against limits.memory: 2 hexahedra x 8^4
  json big = beam_scene();
  big["refinement"] = json::parse(R"({"max_level": 5, "pre_refine": [{"where": {"type": "all"}, "levels": 4}]})");
  big["limits"] = json::parse(R"({"memory": 1e7})");
  CHECK(refused(big).find("meshes[0].cells: the scene needs about 36 MB of memory") == 0);
}

TEST_CASE("scene refinement: what the model cannot take stops the run before it starts") {
  json j = beam_scene();
  j["refinement"] = json::parse(R"({"criteria": [{"type": "contact"}]})");
  CHECK(run_refused(j) == "refinement.criteria[0]: \"contact\" needs obstacles, and the scene has none");
  j["refinement"] = json::parse(R"({"pre_refine": [{"where": {"type": "box", "min": [5, 5, 5], "max": [6, 6, 6]}}]})");
  CHECK(run_refused(j) == "refinement.pre_refine[0].where: holds the rest centroid of no hexahedron");
  json tets = beam_scene();
  tets["meshes"][0]["type"] = "tet_grid";
  tets["refinement"] = json::parse(R"({"pre_refine": [{"where": {"type": "all"}}]})");
  CHECK(run_refused(tets).find("refinement: refines hexahedra, and the meshes have none") == 0);
  tets["model"] = json::parse(R"({"type": "solid"})");
  tets["damping"] = json::parse(R"({"model": "none"})");
  CHECK(run_refused(tets) == "refinement: refines the mass-spring model only (model.type is \"solid\")");
  // adaptive refinement past limits.memory stops the run, naming the key to change
  json grow = beam_scene();
  grow["refinement"] = json::parse(R"({"criteria": [{"type": "region", "where": {"type": "all"}}], "max_level": 4})");
  grow["limits"] = json::parse(R"({"memory": 1e6})");  // 227 hexahedra: the second pass (16 -> 128) fits, the third not
  CHECK(run_refused(grow).find("refinement.max_level: adaptive refinement: refining the 128 elements") == 0);
}

TEST_CASE("scene refinement: the Table 1 beam refined adaptively by the run") {
  json j = beam_scene();
  j["refinement"] = json::parse(R"({"criteria": [{"type": "diagonal_strain", "threshold": 1.2}], "max_level": 3,
                                    "pre_refine": [{"where": {"type": "all"}}]})");
  RunOptions o;
  o.quiet = true;
  o.out = std::filesystem::temp_directory_path() / "sewn_refine_keys_beam";
  const RunSummary s = run(parse_scene(j, "beam.json"), o);
  // the 2 roots pre-refined, then some of their 16 children as the beam sags: never past level 3
  CHECK(s.refined > 2);
  CHECK(s.refined <= 2 + 16);
  std::ifstream csv(s.csv);
  std::string header, row, last;
  std::getline(csv, header);
  while (std::getline(csv, row)) last = row;
  CHECK(header.find(",refined,coarsened") != std::string::npos);
  // the last frame's element count is 16 + 7 per refined child
  CHECK(csv_value(header, last, "elements") == 16 + 7 * static_cast<double>(s.refined - 2));

  // with 2:1 balance: the same run, balanced refinements counted with the criterion's
  json balanced = j;
  balanced["refinement"]["balance"] = true;
  const Scene bs = parse_scene(balanced, "beam.json");
  CHECK(bs.refinement.balance);
  const RunSummary b = run(bs, o);
  CHECK(b.refined >= s.refined);
  CHECK(b.refined <= 2 + 16);

  // without refinement, the same scene keeps its two elements
  json plain = beam_scene();
  CHECK(run(parse_scene(plain, "beam.json"), o).refined == 0);
}

TEST_CASE("scene surface meshes: voxelized, refined, and skipped when optional and absent") {
  const auto dir = std::filesystem::temp_directory_path() / "sewn_refine_keys_surface";
  std::filesystem::create_directories(dir);
  {
    // a 2 m x 1 m x 1 m box, its faces as quads (outward)
    std::ofstream off(dir / "box.off");
    off << "OFF\n8 6 0\n0 0 0\n2 0 0\n2 1 0\n0 1 0\n0 0 1\n2 0 1\n2 1 1\n0 1 1\n"
           "4 0 3 2 1\n4 4 5 6 7\n4 0 1 5 4\n4 2 3 7 6\n4 1 2 6 5\n4 0 4 7 3\n";
  }
  json j = beam_scene();
  j["meshes"] = json::parse(R"([{"type": "surface", "material": "paper", "path": "box.off", "resolution": 4}])");
  j["refinement"] = json::parse(R"({"pre_refine": [{"where": {"type": "box", "min": [-1, -1, -1], "max": [0.5, 2, 2]}}]})");
  j["duration"] = 0.002;
  const Scene s = parse_scene(j, (dir / "scene.json").string());
  CHECK(s.skip.empty());
  CHECK(s.meshes[0].path == (dir / "box.off").string());
  RunOptions o;
  o.quiet = true;
  o.out = dir / "out";
  const RunSummary r = run(s, o);
  CHECK(r.refined == 4);  // the 4 x 2 x 2 cubes of side 0.5 m: the 4 with x < 0.5 refined
  std::ifstream csv(r.csv);
  std::string header, row;
  std::getline(csv, header);
  std::getline(csv, row);
  // 5 x 3 x 3 particles, of which the refined block 0.5 x 1 x 1 had 2 x 3 x 3, now 3 x 5 x 5
  CHECK(csv_value(header, row, "particles") == 45 - 18 + 75);
  CHECK(csv_value(header, row, "elements") == 16 - 4 + 32);
  // a missing file: an error naming it, or a skipped scene when the scene says so
  j["meshes"][0]["path"] = "none.off";
  const Scene missing = parse_scene(j, (dir / "scene.json").string());
  CHECK(missing.skip.empty());
  CHECK_THROWS_WITH(run(missing, o), doctest::Contains("none.off: no such file"));
  j["meshes"][0]["missing"] = "skip";
  CHECK(parse_scene(j, (dir / "scene.json").string()).skip == "meshes[0].path: " + (dir / "none.off").string() + " is not present");
  // the memory estimate counts the whole grid of resolution³ cells
  j["meshes"][0]["resolution"] = 1024;
  CHECK(refused(j).find("meshes[0].resolution: the scene needs about") == 0);
  std::filesystem::remove_all(dir);
}

}  // namespace refine_keys_test
