// The scene key `obstacles`: every type read with its defaults, bad values refused with the
// key path, and a run where the ground stops a falling cube (without it, the cube falls on).
#include <doctest/doctest.h>

#include <filesystem>
#include <string>

#include "sewn/apps/runner.hpp"
#include "sewn/apps/scene.hpp"
#include "scratch.hpp"

namespace test_obstacle_keys {

using namespace sewn::app;
using nlohmann::json;

namespace {

json cube_scene() {
  return json::parse(R"({
    "materials": {"rubber": {"young": 2e5, "density": 500}},
    "meshes": [{"type": "hex_grid", "material": "rubber", "cells": [2, 2, 2], "size": [0.1, 0.1, 0.1],
                "origin": [-0.05, -0.05, 0.05]}],
    "damping": {"environment": 2},
    "duration": 1.5,
    "output": {"vtu": false, "csv": false, "picture": {"enabled": false}}
  })");
}

std::string error_path(const json& j) {
  try {
    (void)parse_scene(j, "bad.json");
  } catch (const SceneError& e) {
    return e.path() + ": " + e.reason();
  }
  return "accepted";
}

}  // namespace

TEST_CASE("scene obstacles: every type with its defaults") {
  json j = cube_scene();
  j["obstacles"] = json::parse(R"([
    {"type": "plane", "friction": 0.4},
    {"type": "sphere", "center": [0, 0, -1], "radius": 0.5, "stiffness": 2e4},
    {"type": "box", "min": [1, 1, 1], "max": [2, 3, 4]},
    {"type": "cone", "apex": [0, 0, 1], "half_angle": 0.3, "height": 0.5}
  ])");
  const Scene s = parse_scene(j, "scene.json");
  REQUIRE(s.obstacles.size() == 4);
  using namespace sewn::physics::obstacles;
  const auto& plane = std::get<Plane>(s.obstacles[0].shape);
  CHECK(plane.normal.z() == 1.0);
  CHECK(plane.friction == 0.4);
  CHECK(s.obstacles[0].stiffness == 1e5);
  CHECK(s.obstacles[0].friction_velocity == 1e-3);
  CHECK(s.obstacles[1].stiffness == 2e4);
  const auto& box = std::get<Box>(s.obstacles[2].shape);
  CHECK(box.center.isApprox(Eigen::Vector3d(1.5, 2, 2.5)));
  CHECK(box.half_extents.isApprox(Eigen::Vector3d(0.5, 1, 1.5)));
  CHECK(std::get<Cone>(s.obstacles[3].shape).axis.z() == -1.0);
  CHECK(parse_scene(cube_scene(), "scene.json").obstacles.empty());
}

TEST_CASE("scene obstacles: bad values name the key") {
  auto with = [](const char* text) {
    json j = cube_scene();
    j["obstacles"] = json::parse(text);
    return error_path(j);
  };
  CHECK(with(R"([{"type": "plane", "normal": [0, 0, 0]}])").find("obstacles[0].normal: must not be zero") == 0);
  CHECK(with(R"([{"type": "box", "min": [0, 0, 0], "max": [1, 0, 1]}])").find("obstacles[0].max") == 0);
  CHECK(with(R"([{"type": "sphere", "center": [0, 0, 0], "radius": -1}])").find("obstacles[0].radius") == 0);
  CHECK(with(R"([{"type": "cone", "apex": [0, 0, 0], "half_angle": 2, "height": 1}])").find("obstacles[0].half_angle") == 0);
  CHECK(with(R"([{"type": "sphere", "center": [0, 0, 0], "radius": 1, "stiffness": 0}])").find("obstacles[0].stiffness") == 0);
  CHECK(with(R"([{"type": "spere", "center": [0, 0, 0], "radius": 1}])").find("did you mean \"sphere\"") != std::string::npos);
  CHECK(with(R"([{"type": "plane", "friction": -0.1}])").find("obstacles[0].friction") == 0);
}

TEST_CASE("scene obstacles: the ground stops a falling cube") {
  RunOptions opt;
  opt.quiet = true;
  opt.frames = 2;
  opt.out = sewn::test::scratch("obstacle_keys/run");
  json free_fall = cube_scene();
  const RunSummary fall = run(parse_scene(free_fall, "fall.json"), opt);
  json grounded = cube_scene();
  grounded["obstacles"] = json::parse(R"([{"type": "plane", "friction": 0.5, "stiffness": 2e4}])");
  const RunSummary rest = run(parse_scene(grounded, "ground.json"), opt);
  MESSAGE("kinetic energy at the end: falling " << fall.kinetic_end << " J, on the ground " << rest.kinetic_end
                                                << " J (largest " << rest.kinetic_max << " J)");
  CHECK(fall.kinetic_end == doctest::Approx(fall.kinetic_max));  // still accelerating
  CHECK(rest.kinetic_end < 1e-4 * rest.kinetic_max);
  std::filesystem::remove_all(opt.out);
}

}  // namespace test_obstacle_keys
