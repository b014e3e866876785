// What fuzzing the scene reader found (issue 19), one case each: values that used to crash,
// wrap, truncate or write outside the output folder are refused with file, key path and reason.
#include <doctest/doctest.h>

#include <unistd.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <string>

#include "sewn/apps/runner.hpp"
#include "minimal_scene.hpp"
#include "sewn/apps/scene.hpp"
#include "sewn/physics/errors.hpp"
#include "scratch.hpp"

namespace fs = std::filesystem;
namespace test_scene_robustness {

using namespace sewn::app;
using nlohmann::json;

namespace {

constexpr std::size_t max_json_depth_for_test = 64;

using sewn::app::test::minimal;

void expect_refused(const json& j, const std::string& path, const std::string& reason) {
  try {
    parse_scene(j, "bad.json");
    FAIL("accepted; expected a refusal at " << path);
  } catch (const SceneError& e) {
    CHECK(e.path() == path);
    CHECK_MESSAGE(e.reason().find(reason) != std::string::npos, "reason: " << e.reason());
  }
}

fs::path scratch_file(const std::string& name, const std::string& text) { return sewn::test::scratch_file("robust/" + name, text); }

void expect_file_refused(const std::string& text, const std::string& path, const std::string& reason) {
  const fs::path f = scratch_file("scene.json", text);
  try {
    load_scene(f.string());
    FAIL("accepted; expected a refusal at " << path);
  } catch (const SceneError& e) {
    CHECK(e.file() == f.string());
    CHECK(e.path() == path);
    CHECK_MESSAGE(e.reason().find(reason) != std::string::npos, "reason: " << e.reason());
  }
}

}  // namespace

TEST_CASE("integer keys refuse numbers they cannot hold instead of casting them") {
  struct Case {
    const char* pointer;
    const char* value;
    const char* path;
    const char* reason;
  };
  const Case cases[] = {
      // a tag of 2^32 used to wrap to 0, the tag of every generated cell: every particle fixed
      {"/fixed", R"([{"where": {"type": "tag", "tag": 4294967296}}])", "fixed[0].where.tag", "<= 2147483647"},
      {"/fixed", R"([{"where": {"type": "tag", "tag": 1e300}}])", "fixed[0].where.tag", "whole number"},
      {"/fixed", R"([{"where": {"type": "tag", "tag": 0.7}}])", "fixed[0].where.tag", "whole number"},
      {"/fixed", R"([{"where": {"type": "points", "indices": [5e9]}}])", "fixed[0].where.indices[0]", "<= 4294967294"},
      {"/fixed", R"([{"where": {"type": "points", "indices": [4294967296]}}])", "fixed[0].where.indices[0]", "<= 4294967294"},
      {"/fixed", R"([{"where": {"type": "points", "indices": [0.7]}}])", "fixed[0].where.indices[0]", "whole number"},
      {"/fixed", R"([{"where": {"type": "points", "indices": [-1]}}])", "fixed[0].where.indices[0]", ">= 0"},
      {"/cuts", R"([{"type": "particles", "time": 0, "particles": [1, 1e300]}])", "cuts[0].particles[1]", "<= 4294967294"},
      {"/cuts", R"([{"type": "particles", "time": 0, "particles": [1, 2.5]}])", "cuts[0].particles[1]", "whole number"},
      {"/cuts", R"([{"type": "faces", "time": 0, "faces": [[0, 1, 2, 5e9]]}])", "cuts[0].faces[0][3]", "<= 4294967294"},
      {"/cuts", R"([{"type": "faces", "time": 0, "faces": [[0, 1, -2, 3]]}])", "cuts[0].faces[0][2]", ">= 0"},
      {"/meshes/0/cells", "[4, 1, 1e300]", "meshes[0].cells[2]", "<= 4096"},
      {"/meshes/0/cells", "[4, 1, 0.7]", "meshes[0].cells[2]", "whole number"},
      {"/meshes/0", R"({"type": "boxes", "material": "steel", "spacing": [1, 1, 1], "boxes": [{"min": [0, 0, 0], "max": [1, 1, 1e300]}]})",
       "meshes[0].boxes[0].max[2]", "<= 1000000"},
      {"/meshes/0", R"({"type": "disc", "material": "steel", "radius": 1, "rings": 5e9})", "meshes[0].rings", "whole number"},
      {"/output", R"({"frames": 4294967297})", "output.frames", "<= 100000"},
      {"/integrator", R"({"max_iterations": -1})", "integrator.max_iterations", ">= 1"},
  };
  for (const auto& c : cases) {
    CAPTURE(c.value);
    json j = minimal();
    j[json::json_pointer(c.pointer)] = json::parse(c.value);
    expect_refused(j, c.path, c.reason);
  }
  // in range: read exactly
  json j = minimal();
  j["fixed"] = json::parse(R"([{"where": {"type": "tag", "tag": -2147483648}}, {"where": {"type": "points", "indices": [4294967294]}}])");
  const Scene s = parse_scene(j, "ok.json");
  CHECK(s.fixed[0].where.tag == -2147483648);
  CHECK(s.fixed[1].where.points == std::vector<std::uint32_t>{4294967294u});
}

TEST_CASE("the scene name is a plain file name, so outputs stay in the output folder") {
  for (const char* bad : {"../x", "/tmp/x", "a/b", "..", ".", "a\\b", "tab\there", "nl\nx"}) {
    CAPTURE(bad);
    json j = minimal();
    j["name"] = bad;
    expect_refused(j, "name", std::string(bad) == "tab\there" || std::string(bad) == "nl\nx" ? "control character" : "plain file name");
  }
  json j = minimal();
  j["name"] = std::string(300, 'n');
  expect_refused(j, "name", "300 bytes long");
  j["name"] = std::string(100, 'n');
  CHECK(parse_scene(j, "ok.json").name == std::string(100, 'n'));
  j["name"] = "beam 2 (E=1e6)";
  CHECK(parse_scene(j, "ok.json").name == "beam 2 (E=1e6)");
  // no name: the file's, which must qualify too
  j.erase("name");
  CHECK(parse_scene(j, "dir/beam.json").name == "beam");
  CHECK_THROWS_WITH_AS(parse_scene(j, "dir/" + std::string(300, 'f') + ".json"), doctest::Contains("name: is not set"),
                       SceneError);
}

TEST_CASE("a number too large for a double is refused with its key path, not as a failed run") {
  // nlohmann's reader refuses 1e999 with a byte offset only; the tool used to report "the run failed"
  expect_file_refused(R"({"materials": {"m": {"young": 1e999, "density": 1000}}, "meshes": []})", "materials.m.young",
                      "1e999 is out of range");
  expect_file_refused(R"({"gravity": [0, 0, -1e400]})", "gravity[2]", "out of range");
  expect_file_refused(R"({"meshes": [{"type": "polyline", "points": [[0, 0, 0], [1, 1, -2e308]]}]})", "meshes[0].points[1][2]",
                      "out of range");
  // finite but beyond any material: the run used to fail on NaN in the solver (exit 1, no key)
  json j = minimal();
  j["materials"]["steel"]["young"] = 1e308;
  expect_refused(j, "materials.steel.young", "<= 10000000000000");
  j = minimal();
  j["materials"]["steel"]["density"] = 1e308;
  expect_refused(j, "materials.steel.density", "<= 100000");
  j = minimal();
  j["gravity"] = {0, 0, -1e308};
  expect_refused(j, "gravity[2]", ">= -1000000");
  j = minimal();
  j["damping"] = {{"environment", 1e308}};
  expect_refused(j, "damping.environment", "<= 1000000");
  // a key given twice would silently keep the last value
  expect_file_refused(R"({"duration": 1, "materials": {}, "duration": 2})", "duration", "appears twice");
  // syntax errors keep their line
  expect_file_refused("{\n\"a\": [1,\n 2,,]}", "line 3", "not valid JSON");
}

TEST_CASE("nesting 10^4 deep is refused with the path where it crosses the limit, without exhausting the stack") {
  const std::string deep = std::string(10000, '[') + std::string(10000, ']');
  std::string at_limit = "x";
  for (std::size_t i = 0; i + 1 < max_json_depth_for_test; ++i) at_limit += "[0]";
  expect_file_refused("{\"x\": " + deep + "}", at_limit, "nested more than 64 levels");
  std::string in_material = "materials.m.young";
  for (std::size_t i = 0; i + 2 < max_json_depth_for_test - 1; ++i) in_material += "[0]";
  expect_file_refused(R"({"materials": {"m": {"young": )" + deep + "}}}", in_material, "nested more than 64 levels");
  // the same value given to parse_scene directly (no file): the message describes it without
  // walking it
  json j = minimal();
  json v = json::array();
  for (int i = 0; i < 10000; ++i) v = json::array({std::move(v)});
  j["materials"]["steel"]["young"] = std::move(v);
  expect_refused(j, "materials.steel.young", "a list of 1 entry");
}

TEST_CASE("sizes that would exhaust memory or time are refused when the scene is read, unless a limit is raised") {
  json j = minimal();
  j["meshes"][0]["cells"] = {4096, 4096, 4096};  // reserved 1.6 TB before
  expect_refused(j, "meshes[0].cells", "TB of memory");
  expect_refused(j, "meshes[0].cells", "limits.memory");
  j["meshes"][0] = json::parse(R"({"type": "disc", "material": "steel", "radius": 1, "rings": 10000, "sectors": 10000})");
  expect_refused(j, "meshes[0].rings", "PB of memory");
  j["meshes"][0] = json::parse(R"({"type": "tri_grid", "material": "steel", "cells": [65536, 65536], "size": [1, 1]})");
  expect_refused(j, "meshes[0].cells", "of memory");
  j["meshes"][0] = json::parse(R"({"type": "cylinder", "material": "steel", "radius": 1, "height": 1, "rings": 1000, "sectors": 1000, "layers": 10000})");
  expect_refused(j, "meshes[0].layers", "of memory");
  j["meshes"][0] = json::parse(R"({"type": "boxes", "material": "steel", "spacing": [1, 1, 1], "boxes": [{"min": [-1000000, -1000000, 0], "max": [1000000, 1000000, 1]}]})");
  expect_refused(j, "meshes[0].boxes", "of memory");
  // several meshes each under the limit, together over it: the largest is named
  j = minimal();
  j["meshes"] = json::array();
  for (int i = 0; i < 3; ++i) j["meshes"].push_back(json::parse(R"({"type": "hex_grid", "material": "steel", "cells": [100, 100, 100], "size": [1, 1, 1]})"));
  j["meshes"][2]["cells"] = {120, 100, 100};
  expect_refused(j, "meshes[2].cells", "of memory");
  // a raised limit lets the scene through (nothing is built when a scene is read)
  j["limits"] = {{"memory", 1e11}};
  CHECK(parse_scene(j, "ok.json").meshes.size() == 3);

  j = minimal();
  j["integrator"] = {{"step", 1e-12}};
  expect_refused(j, "integrator.step", "1e+12 steps");
  j["integrator"] = {{"step", 5e-324}};
  j["duration"] = 1e6;
  expect_refused(j, "integrator.step", "inf steps");
  j["integrator"] = {{"step", 1e-9}};
  j["duration"] = 1;
  expect_refused(j, "integrator.step", "limits.steps");
  j["limits"] = {{"steps", 1e9}};
  CHECK(parse_scene(j, "ok.json").step == 1e-9);
  j["limits"] = {{"steps", 0}};
  expect_refused(j, "limits.steps", "must be > 0");
}

TEST_CASE("a picture the renderer cannot draw is refused when the scene is read") {
  json j = minimal();
  j["output"] = {{"picture", {{"width", 64}}}};
  expect_refused(j, "output.picture.width", ">= 200");
  j["output"] = {{"picture", {{"height", 100}}}};
  expect_refused(j, "output.picture.height", ">= 150");
  j["output"] = {{"picture", {{"width", 200}, {"height", 150}}}};
  CHECK(parse_scene(j, "ok.json").width == 200);
}

TEST_CASE("a folder given as the scene is refused as such") {
  const fs::path dir = scratch_file("x.json", "{}").parent_path();
  CHECK_THROWS_WITH_AS(load_scene(dir.string()), doctest::Contains("is a folder, not a scene file"), SceneError);
  CHECK_THROWS_WITH_AS(load_scene((dir / std::string(300, 'n')).string() + ".json"), doctest::Contains("name too long"), SceneError);
}

TEST_CASE("a mass that underflows to zero is refused when the model is built") {
  // density 1e-320 used to give the points no particle, leaving their darts linked to node
  // 0xffffffff: an out-of-bounds write. Subnormal masses are refused too (no usable inverse).
  for (const char* density : {"1e-320", "1e-310"}) {
    CAPTURE(density);
    json j = minimal();
    j["materials"]["steel"]["density"] = json::parse(density);
    j["duration"] = 0.01;
    RunOptions opt;
    opt.quiet = true;
    opt.out = scratch_file("x", "").parent_path() / "mass_out";
    CHECK_THROWS_WITH_AS(run(parse_scene(j, "light.json"), opt), doctest::Contains("underflows"), sewn::physics::InputError);
  }
  // the same scene with its ordinary density runs
  json j = minimal();
  j["duration"] = 0.002;
  j["output"] = {{"vtu", false}, {"csv", false}, {"picture", {{"enabled", false}}}};
  RunOptions opt;
  opt.quiet = true;
  opt.out = scratch_file("x", "").parent_path() / "mass_ok";
  CHECK_NOTHROW(run(parse_scene(j, "light.json"), opt));
}

TEST_CASE("a material region that selects no cell is refused, not ignored") {
  // It left every cell in the mesh's material and the run went on: a Gmsh volume in two
  // physical groups carries the first one's tag only, so a region by the second group's tag
  // made a soft part as stiff as the rest without a word.
  json j = minimal();
  j["materials"]["rubber"] = {{"young", 1e6}, {"density", 1000}};
  j["meshes"][0]["regions"] = json::array({{{"where", {{"type", "box"}, {"min", {0, 0, 0}}, {"max", {0.3, 1, 1}}}}, {"material", "rubber"}},
                                           {{"where", {{"type", "tag"}, {"tag", 3}}}, {"material", "rubber"}}});
  try {
    (void)assemble(parse_scene(j, "regions.json"));
    FAIL("accepted a region that selects nothing");
  } catch (const SceneError& e) {
    CHECK(e.path() == "meshes[0].regions[1].where");
    CHECK(e.reason().find("selects no simulated cell of this mesh") == 0);
    CHECK(e.reason().find("first physical group") != std::string::npos);
  }
  j["meshes"][0]["regions"].erase(1);  // the box region selects the first cell: accepted
  const Assembly a = assemble(parse_scene(j, "regions.json"));
  CHECK(std::count(a.material_of_cell.begin(), a.material_of_cell.end(), a.material_of_cell[0]) == 1);
}

}  // namespace test_scene_robustness
