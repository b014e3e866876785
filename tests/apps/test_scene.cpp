// Scene files: every documented key validated, every invalid value refused with file, key path
// and reason; the reference documentation is generated from the same schema.
#include <doctest/doctest.h>

#include <fstream>
#include <sstream>
#include <string>

#include "minimal_scene.hpp"
#include "sewn/apps/scene.hpp"
#include "sewn/physics/integrators.hpp"

namespace test_scene {

using namespace sewn::app;
using nlohmann::json;

namespace {

using sewn::app::test::minimal;

// Expects parse_scene to throw a SceneError whose key path is `path` and whose reason contains
// `reason`.
void expect_error(const json& j, const std::string& path, const std::string& reason) {
  CAPTURE(j.dump());
  try {
    parse_scene(j, "bad.json");
    FAIL("accepted an invalid scene; expected an error at " << path);
  } catch (const SceneError& e) {
    CHECK(e.file() == "bad.json");
    CHECK(e.path() == path);
    CHECK_MESSAGE(e.reason().find(reason) != std::string::npos, "reason: " << e.reason());
    CHECK(std::string(e.what()).find("bad.json: " + path) == 0);
  }
}

}  // namespace

TEST_CASE("a minimal scene gets the documented defaults") {
  const Scene s = parse_scene(minimal(), "dir/beam.json");
  CHECK(s.name == "beam");
  CHECK(s.materials.at("steel").poisson == doctest::Approx(0.3));
  CHECK(s.integrator == "implicit");
  CHECK(s.step == doctest::Approx(1e-3));
  CHECK(s.gravity[2] == doctest::Approx(-9.81));
  CHECK(s.damping == "viscous");
  CHECK(s.frames == 50);
  CHECK(s.meshes[0].cells == std::array<std::uint32_t, 3>{4, 1, 1});
  CHECK(s.meshes[0].origin == Vec3{0, 0, 0});
  CHECK(s.write_picture);
}

TEST_CASE("the default scene parses and describes a cut cantilever") {
  const Scene s = default_scene();
  CHECK(s.name == "default");
  CHECK(s.meshes.size() == 1);
  CHECK(s.meshes[0].type == "hex_grid");
  CHECK(s.fixed.size() == 1);
  CHECK(s.cuts.size() == 1);
  CHECK(s.cuts[0].type == "plane");
  REQUIRE(s.cuts[0].within.has_value());
  CHECK(s.cuts[0].within->type == Selector::Type::box);
}

TEST_CASE("unknown keys name the closest known key") {
  json j = minimal();
  j["materials"]["steel"]["yung"] = 1;
  expect_error(j, "materials.steel.yung", "did you mean \"young\"");
  j = minimal();
  j["gravty"] = {0, 0, -1};
  expect_error(j, "gravty", "did you mean \"gravity\"");
  j = minimal();
  j["meshes"][0]["type"] = "hexgrid";
  expect_error(j, "meshes[0].type", "did you mean \"hex_grid\"");
  j = minimal();
  j["integrator"] = {{"type", "implict"}};
  expect_error(j, "integrator.type", "did you mean \"implicit\"");
  j = minimal();
  j["meshes"][0]["radius"] = 1;  // a key of another mesh kind
  expect_error(j, "meshes[0].radius", "unknown key");
}

TEST_CASE("invalid values are refused with the key path and the reason") {
  struct Case {
    const char* pointer;
    const char* value;
    const char* path;
    const char* reason;
  };
  // value: JSON text put at `pointer` in the minimal scene
  const Case cases[] = {
      {"/materials/steel/young", "-1e9", "materials.steel.young", "must be > 0"},
      {"/materials/steel/young", "0", "materials.steel.young", "must be > 0"},
      {"/materials/steel/young", "\"hard\"", "materials.steel.young", "expected a number in Pa"},
      {"/materials/steel/poisson", "0.5", "materials.steel.poisson", "< 0.5"},
      {"/materials/steel/poisson", "0.7", "materials.steel.poisson", "< 0.5"},
      {"/materials/steel/density", "-3", "materials.steel.density", "must be > 0"},
      {"/integrator", R"({"step": 0})", "integrator.step", "must be > 0"},
      {"/integrator", R"({"step": -0.1})", "integrator.step", "must be > 0"},
      {"/integrator", R"({"tolerance": 2})", "integrator.tolerance", "< 1"},
      {"/integrator", R"({"max_iterations": 2.5})", "integrator.max_iterations", "whole number"},
      {"/duration", "0", "duration", "must be > 0"},
      {"/gravity", "[0, 0]", "gravity", "exactly 3 numbers"},
      {"/gravity", R"([0, "down", 0])", "gravity[1]", "expected a number"},
      {"/meshes/0/cells", "[4, 0, 1]", "meshes[0].cells[1]", ">= 1"},
      {"/meshes/0/cells", "[4, 1.5, 1]", "meshes[0].cells[1]", "whole number"},
      {"/meshes/0/size", "[1, -1, 1]", "meshes[0].size[1]", "must be > 0"},
      {"/meshes/0/material", "\"wood\"", "meshes[0].material", "no material named \"wood\""},
      {"/meshes", "[]", "meshes", "between 1"},
      {"/meshes/0", R"({"type": "boxes", "material": "steel", "spacing": [1, 1, 1], "boxes": []})", "meshes[0].boxes",
       "between 1"},
      {"/meshes/0", R"({"type": "boxes", "material": "steel", "spacing": [1, 1, 1], "boxes": [{"min": [0, 0, 0], "max": [1, 1.5, 1]}]})",
       "meshes[0].boxes[0].max[1]", "whole number"},
      {"/meshes/0", R"({"type": "boxes", "material": "steel", "spacing": [1, 1, 1], "boxes": [{"min": [0, 0, 0], "max": [1, 1, 1]}, {"min": [0, 0, 0], "max": [1, 0, 1]}]})",
       "meshes[0].boxes[1]", "max must exceed min"},
      {"/meshes/0", R"({"type": "boxes", "material": "steel", "spacing": [1, 0, 1], "boxes": [{"min": [0, 0, 0], "max": [1, 1, 1]}]})",
       "meshes[0].spacing[1]", "must be > 0"},
      {"/meshes/0", R"({"type": "boxes", "material": "steel", "spacing": [1, 1, 1], "boxes": [{"min": [0, 0, 0]}]})",
       "meshes[0].boxes[0].max", "missing"},
      {"/fixed", R"([{"where": {"type": "box", "min": [0, 0, 0]}}])", "fixed[0].where.max", "missing"},
      {"/fixed", R"([{"where": {"type": "sphere", "center": [0, 0, 0], "radius": -1}}])", "fixed[0].where.radius",
       "must be > 0"},
      {"/fixed", R"([{"where": {"type": "all"}, "axes": "w"}])", "fixed[0].axes", "not one of"},
      {"/cuts", R"([{"type": "plane", "time": 0.5, "point": [0, 0, 0], "normal": [0, 0, 0]}])", "cuts[0].normal",
       "must not be zero"},
      {"/cuts", R"([{"type": "plane", "time": 5, "point": [0, 0, 0], "normal": [1, 0, 0]}])", "cuts[0].time",
       "after the end"},
      {"/cuts", R"([{"type": "slice", "time": 0}])", "cuts[0].type", "not one of"},
      {"/cuts", R"([{"time": 0}])", "cuts[0].type", "missing"},
      {"/output", R"({"frames": 0})", "output.frames", ">= 1"},
      {"/output", R"({"picture": {"color_by": "heat"}})", "output.picture.color_by", "not one of"},
  };
  for (const auto& c : cases) {
    json j = minimal();
    j[json::json_pointer(c.pointer)] = json::parse(c.value);
    expect_error(j, c.path, c.reason);
  }
  json nan_scene = minimal();
  nan_scene["duration"] = std::numeric_limits<double>::quiet_NaN();  // serialises as null
  expect_error(nan_scene, "duration", "must be finite");
  json missing = minimal();
  missing.erase("materials");
  expect_error(missing, "materials", "missing");
  expect_error(json::array(), "", "expected an object");
}

TEST_CASE("files: missing, unreadable JSON with its line") {
  CHECK_THROWS_WITH_AS(load_scene("/nonexistent/scene.json"), doctest::Contains("no such file"), SceneError);
  const std::string path = "test_scene_broken.json";
  {
    std::ofstream out(path);
    out << "{\n  \"materials\": {\n    \"a\": { \"young\": 1e6, }\n  }\n}\n";
  }
  try {
    load_scene(path);
    FAIL("accepted broken JSON");
  } catch (const SceneError& e) {
    CHECK(e.path() == "line 3");
    CHECK(e.reason().find("not valid JSON") != std::string::npos);
  }
  std::remove(path.c_str());
}

TEST_CASE("docs/scenes.md is the documentation generated from the schema") {
  const std::string generated = to_markdown(scene_schema(), "Scene files");
  std::ifstream in(std::string(SEWN_SOURCE_DIR) + "/docs/scenes.md");
  REQUIRE_MESSAGE(in, "docs/scenes.md is missing: regenerate it with `sewn scene-doc > docs/scenes.md`");
  std::stringstream text;
  text << in.rdbuf();
  CHECK_MESSAGE(text.str().find(generated) != std::string::npos,
                "docs/scenes.md is out of date: regenerate it with `sewn scene-doc > docs/scenes.md`");
  // every key of every object appears in the reference with its unit
  for (const char* key : {"`young`", "`poisson`", "`density`", "`step`", "`tolerance`", "`allow_unstable`", "`frames`",
                          "`color_by`", "`elongated`", "`within`", "`remove`"})
    CHECK(generated.find(key) != std::string::npos);
  CHECK(generated.find("| Pa |") != std::string::npos);
  CHECK(generated.find("kg/m³") != std::string::npos);
}

TEST_CASE("integrator.solver and the solver defaults: one iteration limit for the library and the tool") {
  const Scene s = parse_scene(minimal(), "beam.json");
  CHECK(s.solver == "auto");
  // issue 17: the tool's defaults are the library's (they disagreed: 2000 against 1000)
  const sewn::physics::ImplicitEulerOptions lib;
  CHECK(s.max_iterations == static_cast<std::uint32_t>(lib.cg_max_iterations));
  CHECK(s.tolerance == lib.cg_tolerance);
  CHECK(s.absolute_tolerance == lib.cg_absolute_tolerance);
  CHECK(s.absolute_acceleration == lib.cg_absolute_acceleration);
  for (auto b : sewn::physics::solve::available_backends()) {
    json j = minimal();
    j["integrator"]["solver"] = std::string(sewn::physics::solve::to_string(b));
    CHECK(parse_scene(j, "beam.json").solver == sewn::physics::solve::to_string(b));
  }
  json j = minimal();
  j["integrator"] = json::parse(R"({"solver": "lu"})");
  expect_error(j, "integrator.solver", "cholmod");
  j["integrator"] = json::parse(R"({"absolute_tolerance": -1})");
  expect_error(j, "integrator.absolute_tolerance", ">= 0");
  j["integrator"] = json::parse(R"({"absolute_acceleration": -1e-6})");
  expect_error(j, "integrator.absolute_acceleration", ">= 0");
  j["integrator"] = json::parse(R"({"absolute_acceleration": "fast"})");
  expect_error(j, "integrator.absolute_acceleration", "number");
  j["integrator"] = json::parse(R"({"absolute_acceleration": 2e-6})");
  CHECK(parse_scene(j, "beam.json").absolute_acceleration == 2e-6);
}

TEST_CASE("integrator.newton_forcing: inexact Newton on cholmod-pcg only, below 1") {
  json j = minimal();
  CHECK(parse_scene(j, "beam.json").newton_forcing == 0.0);
  j["integrator"] = json::parse(R"({"type": "newton", "solver": "jacobi", "newton_forcing": 0.5})");
  expect_error(j, "integrator.newton_forcing", "cholmod-pcg");
  j["integrator"] = json::parse(R"({"type": "implicit", "newton_forcing": 0.5})");
  expect_error(j, "integrator.newton_forcing", "newton");
  j["integrator"] = json::parse(R"({"type": "newton", "solver": "cholmod-pcg", "newton_forcing": 1.5})");
  expect_error(j, "integrator.newton_forcing", "< 1");
  if (!sewn::physics::solve::available(sewn::physics::solve::Backend::cholmod_pcg)) return;
  j["integrator"] = json::parse(R"({"type": "newton", "solver": "cholmod-pcg", "newton_forcing": 0.5})");
  CHECK(parse_scene(j, "beam.json").newton_forcing == 0.5);
}

TEST_CASE("threads: the scene key sets the count, 0 (the default) leaves it to SEWN_THREADS") {
  CHECK(parse_scene(minimal(), "beam.json").threads == 0);
  json j = minimal();
  j["threads"] = 2;
  CHECK(parse_scene(j, "beam.json").threads == 2);
  j["threads"] = -1;
  expect_error(j, "threads", ">= 0");
  j["threads"] = 1.5;
  expect_error(j, "threads", "whole number");
  j["threads"] = 1000;
  expect_error(j, "threads", "256");
}

}  // namespace test_scene
