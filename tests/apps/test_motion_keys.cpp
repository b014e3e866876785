// The scene key `motion` (prescribed rigid motion, issue 16): read with its defaults, bad values
// refused naming the key, and driven particles that land exactly on their prescribed
// trajectory with every integrator while the rest of the body follows with finite energy.
// (Its checkpoint resume is in test_checkpoint.cpp.)
#include <doctest/doctest.h>

#include <cmath>
#include <memory>
#include <numbers>
#include <string>
#include <vector>

#include <Eigen/Geometry>

#include "sewn/apps/runner.hpp"
#include "sewn/apps/scene.hpp"
#include "sewn/cmap/mesh.hpp"
#include "sewn/physics/integrate/implicit_midpoint.hpp"
#include "sewn/physics/integrate/newton_euler.hpp"
#include "sewn/physics/integrators.hpp"
#include "sewn/physics/mss_model.hpp"
#include "scratch.hpp"

namespace test_motion_keys {

namespace {

using nlohmann::json;
using sewn::app::MotionDriver;
using sewn::app::MotionSpec;
using sewn::app::SceneError;
namespace physics = sewn::physics;

// A 1 m soft beam of 4 cubes along x with the motion entries `motion`.
json beam_scene(const std::string& motion) {
  json j = json::parse(R"({
    "materials": {"rubber": {"young": 1e5, "density": 1000}},
    "meshes": [{"type": "hex_grid", "material": "rubber", "cells": [4, 1, 1], "size": [1, 0.25, 0.25]}],
    "damping": {"model": "rayleigh", "alpha": 1},
    "integrator": {"type": "newton", "step": 0.01, "newton_tolerance": 1e-6},
    "duration": 0.1,
    "output": {"vtu": false, "csv": true, "picture": {"enabled": false}}
  })");
  j["motion"] = json::parse(motion);
  return j;
}

// "path: reason" of the SceneError a scene raises when read and then built and run, or "accepted".
std::string error_of(const json& j, bool run = false) {
  try {
    const sewn::app::Scene s = sewn::app::parse_scene(j, "m.json");
    if (run) {
      sewn::app::RunOptions o;
      o.quiet = true;
      o.out = sewn::test::scratch("motion_keys/err");
      (void)sewn::app::run(s, o);
    }
  } catch (const SceneError& e) {
    return e.path() + ": " + e.reason();
  }
  return "accepted";
}

}  // namespace

TEST_CASE("scene motion: read with its defaults") {
  const sewn::app::Scene s = sewn::app::parse_scene(
      beam_scene(R"([{"where": {"type": "box", "min": [0.9, -1, -1], "max": [2, 1, 1]}, "velocity": [0, 0, 0.1]},
                     {"where": {"type": "all"}, "rotate": {"axis": [0, 0, 2], "rate": -3}, "from": 0.02, "until": 0.05}])"),
      "m.json");
  REQUIRE(s.motion.size() == 2);
  REQUIRE(s.motion_where.size() == 2);
  CHECK(s.motion[0].velocity == std::array<double, 3>{0, 0, 0.1});
  CHECK(s.motion[0].rate == 0);
  CHECK(s.motion[0].from == 0);
  CHECK(std::isinf(s.motion[0].until));
  CHECK(s.motion[1].axis == Eigen::Vector3d(0, 0, 1));  // normalised
  CHECK(s.motion[1].center == Eigen::Vector3d::Zero());
  CHECK(s.motion[1].rate == -3);
  CHECK(s.motion[1].until == 0.05);
  CHECK(sewn::app::parse_scene(beam_scene("[]"), "m.json").motion.empty());
}

TEST_CASE("scene motion: bad values name the key") {
  const std::string end = R"({"type": "box", "min": [0.9, -1, -1], "max": [2, 1, 1]})";
  auto with = [&](const std::string& entry) { return error_of(beam_scene("[" + entry + "]")); };
  CHECK(with(R"({"where": )" + end + R"(, "velocity": [1, 0, 0], "from": 0.05, "until": 0.05})").find("motion[0].until: must be after `from`") == 0);
  CHECK(with(R"({"where": )" + end + R"(, "rotate": {"axis": [0, 0, 0], "rate": 1}})") == "motion[0].rotate.axis: must not be zero");
  CHECK(with(R"({"where": )" + end + R"(, "rotate": {"axis": [1, 0, 0]}})").find("motion[0].rotate.rate") == 0);
  CHECK(with(R"({"where": )" + end + "}").find("motion[0]: moves nothing") == 0);
  CHECK(with(R"({"where": )" + end + R"(, "velocity": [1, 0, 0], "from": 0.1})").find("motion[0].from: is not before the end of the run") == 0);
  CHECK(with(R"({"where": )" + end + R"(, "velocity": [1, 0, 0], "from": -1})").find("motion[0].from") == 0);
  CHECK(with(R"({"velocity": [1, 0, 0]})").find("motion[0].where") == 0);
  CHECK(with(R"({"where": )" + end + R"(, "velocity": [1, 0, 0], "speed": 2})").find("motion[0].speed") == 0);

  json cut = beam_scene(R"([{"where": )" + end + R"(, "velocity": [1, 0, 0]}])");
  cut["cuts"] = json::parse(R"([{"type": "plane", "time": 0.05, "point": [0.5, 0, 0], "normal": [1, 0, 0]}])");
  CHECK(error_of(cut).find("motion[0]: prescribed motion cannot be combined with `cuts`") == 0);
  json refined = beam_scene(R"([{"where": )" + end + R"(, "velocity": [1, 0, 0]}])");
  refined["refinement"] = json::parse(R"({"criteria": [{"type": "diagonal_strain", "threshold": 5}]})");
  CHECK(error_of(refined).find("motion[0]: prescribed motion cannot be combined with `refinement`") == 0);

  // found when the particles are selected
  json held = beam_scene(R"([{"where": )" + end + R"(, "velocity": [1, 0, 0]}])");
  held["fixed"] = json::parse(R"([{"where": {"type": "box", "min": [0.99, -1, -1], "max": [2, 1, 1]}, "axes": "z"}])");
  CHECK(error_of(held, true).find("motion[0].where: selects the particle at meshes[0] point ") == 0);
  CHECK(error_of(held, true).find("which `fixed` holds") != std::string::npos);
  CHECK(error_of(beam_scene(R"([{"where": {"type": "box", "min": [5, 5, 5], "max": [6, 6, 6]}, "velocity": [1, 0, 0]}])"), true) ==
        "motion[0].where: selects no particle");
  const std::string overlap = R"([{"where": )" + end + R"(, "velocity": [1, 0, 0], "until": 0.05},
                                  {"where": {"type": "all"}, "velocity": [0, 1, 0], "from": 0.04}])";
  CHECK(error_of(beam_scene(overlap), true).find("motion[1].where: drives the particle at meshes[0] point ") == 0);
  CHECK(error_of(beam_scene(overlap), true).find("which motion[0] drives at overlapping times") != std::string::npos);
  // the same entries one after the other chain
  CHECK(error_of(beam_scene(R"([{"where": )" + end + R"(, "velocity": [1, 0, 0], "until": 0.05},
                                {"where": )" + end + R"(, "velocity": [0, 1, 0], "from": 0.05}])"),
                 true) == "accepted");
}

namespace {

// The beam of 4 soft cubes as a bare model, its end at x = 1 driven by `spec`.
struct DrivenBeam {
  std::unique_ptr<physics::MssModel<3>> model;
  MotionDriver driver;
  std::vector<Eigen::Vector3d> start;  // the driven particles' initial positions
};

DrivenBeam driven_beam(const std::vector<MotionSpec>& specs) {
  DrivenBeam b;
  const sewn::IndexedMesh mesh = sewn::hex_grid(4, 1, 1, sewn::GridSpec{{0.25, 0.25, 0.25}, {0, 0, 0}});
  physics::MssOptions mo;
  mo.damping = physics::DampingModel::rayleigh;
  mo.rayleigh_alpha = 1;
  b.model = std::make_unique<physics::MssModel<3>>(mesh, std::vector<physics::MaterialParams>{{1e5, 0.3, 1000, 1, 1e-4,
                                                                                              physics::ElongatedPolicy::refuse}},
                                                   std::vector<std::uint32_t>{}, mo);
  std::vector<physics::Index> end;
  for (physics::Index i = 0; i < b.model->nodes().size(); ++i)
    if (b.model->rest_position(i).x() > 0.99) end.push_back(i);
  REQUIRE(end.size() == 4);
  b.driver = MotionDriver(specs, std::vector<std::vector<physics::Index>>(specs.size(), end), b.model->nodes(), "beam");
  for (physics::Index i : end) b.start.push_back(b.model->nodes().position(i));
  return b;
}

// The end turning about the beam's axis at 3 rad/s and rising at 0.2 m/s for 0.15 s, then
// (chained) sliding sideways at 0.5 m/s: x(t) by hand.
Eigen::Vector3d expected(const Eigen::Vector3d& x0, double t) {
  const Eigen::Vector3d c(1, 0.125, 0.125), axis(1, 0, 0);
  const double tau = std::min(t, 0.15);
  Eigen::Vector3d x = c + Eigen::Vector3d(0, 0, 0.2) * tau + Eigen::AngleAxisd(3 * tau, axis) * (x0 - c);
  if (t > 0.15) x += Eigen::Vector3d(0, 0.5, 0) * (t - 0.15);
  return x;
}

std::vector<MotionSpec> turn_then_slide() {
  MotionSpec turn;
  turn.velocity = {0, 0, 0.2};
  turn.axis = Eigen::Vector3d(1, 0, 0);
  turn.center = Eigen::Vector3d(1, 0.125, 0.125);
  turn.rate = 3;
  turn.until = 0.15;
  MotionSpec slide;
  slide.velocity = {0, 0.5, 0};
  slide.from = 0.15;
  return {slide, turn};  // out of time order on purpose
}

}  // namespace

TEST_CASE("scene motion: driven particles land on the prescribed trajectory with every integrator") {
  const double h = 0.005;
  const int steps = 50;  // 0.25 s: the turn, then the slide
  auto run = [&](auto& integrator, const char* name) {
    INFO(name);
    DrivenBeam b = driven_beam(turn_then_slide());
    physics::System& sys = b.model->system();
    double worst = 0, energy_max = 0;
    for (int s = 0; s < steps; ++s) {
      const double t = s * h;
      b.driver.drive(b.model->nodes(), t, h);
      (void)integrator.step(sys, h);
      for (std::size_t i = 0; i < b.driver.size(); ++i) {
        const Eigen::Vector3d want = expected(b.start[i], t + h);
        worst = std::max(worst, (b.model->nodes().position(b.driver.node(i)) - want).norm());
        CHECK((b.driver.position(i, t + h) - want).norm() < 1e-14);
      }
      energy_max = std::max(energy_max, sys.kinetic_energy() + sys.potential_energy());
    }
    CHECK(worst < 1e-14);
    CHECK(std::isfinite(energy_max));
    // the body followed: the free end at x = 0 moved (gravity and the pull), and nothing blew up
    CHECK(std::abs(energy_max) > 0);
    CHECK(b.model->nodes().position(0).allFinite());
    // the driven end turned 0.45 rad about x: its particles are no longer level
    CHECK(std::abs((b.model->nodes().position(b.driver.node(1)) - b.model->nodes().position(b.driver.node(0))).z()) > 0.05);
  };
  physics::SymplecticEuler semi;
  physics::LinearlyImplicitEuler implicit;
  physics::ImplicitMidpoint midpoint;
  physics::integrate::NewtonEulerOptions no;
  no.velocity_tolerance = 1e-6;
  physics::integrate::NewtonEuler newton(no);
  run(semi, "semi-implicit");
  run(implicit, "implicit");
  run(midpoint, "midpoint");
  run(newton, "newton");
}

TEST_CASE("scene motion: a run drives the end and reports finite energies") {
  // the beam's end turned a quarter turn about the beam's axis in 0.1 s by `sewn run`'s loop
  json j = beam_scene(R"([{"where": {"type": "box", "min": [0.99, -1, -1], "max": [2, 1, 1]},
                           "rotate": {"axis": [1, 0, 0], "center": [1, 0.125, 0.125], "rate": 15.707963267948966}}])");
  j["output"]["frames"] = 2;
  sewn::app::RunOptions o;
  o.quiet = true;
  o.out = sewn::test::scratch("motion_keys/run");
  const sewn::app::RunSummary sum = sewn::app::run(sewn::app::parse_scene(j, "m.json"), o);
  CHECK(sum.steps == 10);
  CHECK(std::isfinite(sum.kinetic_max));
  CHECK(sum.kinetic_max > 0);
  CHECK(std::isfinite(sum.kinetic_end));
}

}  // namespace test_motion_keys
