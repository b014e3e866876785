// model.connections: the detected and named joints of a mixed scene become point and curve
// connection energies (apps/connections.hpp), with stiffnesses from the materials; the fin scene
// (scenes/mixed_fin.json) then holds a moment at the mast's joint, which a pinned joint cannot.
#include <doctest/doctest.h>

#include <cmath>
#include <functional>
#include <memory>
#include <random>
#include <string>

#include "sewn/apps/connections.hpp"
#include "sewn/apps/continuum.hpp"
#include "sewn/apps/runner.hpp"
#include "sewn/apps/scene.hpp"
#include "sewn/io/cleanup.hpp"
#include "sewn/physics/integrate/newton_euler.hpp"

#include "force_check.hpp"

namespace test_connection_keys {
namespace {

using sewn::app::Scene;
using sewn::app::SceneError;
using sewn::physics::Index;

const std::string fin_path = std::string(SEWN_SOURCE_DIR) + "/scenes/mixed_fin.json";

// The fin scene's model as the runner builds it (bodies, continuum, connections), held by its
// top face (the tag-4 label), at rest.
struct FinModel {
  sewn::app::Assembly assembly;
  std::vector<sewn::physics::MaterialParams> materials;
  std::unique_ptr<sewn::physics::MssModel<3>> model;
  sewn::app::ContinuumParts continuum;
  sewn::app::ConnectionParts joints;
};

std::unique_ptr<FinModel> build_fin(const Scene& scene) {
  auto f = std::make_unique<FinModel>();
  f->assembly = sewn::app::assemble(scene);
  for (const auto& name : f->assembly.material_names) {
    const auto& m = scene.materials.at(name);
    f->materials.push_back({m.young, m.poisson, m.density, m.thickness, m.area, sewn::physics::ElongatedPolicy::refuse});
  }
  sewn::app::apply_rod_sections(scene, f->assembly.mesh, f->assembly.model_of_cell, f->assembly.group_of_cell, f->materials,
                                f->assembly.material_of_cell);
  sewn::physics::MssOptions mo;
  mo.gravity = Eigen::Vector3d(scene.gravity[0], scene.gravity[1], scene.gravity[2]);
  mo.damping = sewn::physics::DampingModel::rayleigh;
  mo.rayleigh_alpha = scene.rayleigh_alpha;
  f->model = std::make_unique<sewn::physics::MssModel<3>>(f->assembly.mesh, f->materials, f->assembly.material_of_cell, mo);
  f->continuum = sewn::app::build_continuum(scene, f->materials, f->assembly.mesh, f->assembly.model_of_cell, f->assembly.group_of_cell,
                                            *f->model);
  f->joints = sewn::app::build_connections(scene, f->assembly.mesh, f->assembly.model_of_cell, f->materials, f->continuum, *f->model);
  const auto& labels = f->assembly.labels;
  for (std::uint32_t c = 0; c < labels.num_cells(); ++c)
    if (labels.tags[c] == 4)
      for (std::uint32_t p : labels.cell(c)) f->model->nodes().fix(f->model->node_of_point(p), sewn::physics::all_axes);
  return f;
}

std::string reason_of(const std::function<void()>& fn) {
  try {
    fn();
  } catch (const SceneError& e) {
    return e.path() + ": " + e.reason();
  }
  return "accepted";
}

// The mast's tilt from the fin's own turn: the angle between the mast's chord (top to tip) now
// and at rest, after `steps` backward Euler steps under a sideways pull of gravity in the fin's
// plane (+x), which a pinned mast swings along and a clamped one resists with a moment.
double mast_tilt(bool connections, int steps) {
  Scene scene = sewn::app::load_scene(fin_path);
  scene.gravity = {9.81, 0, -9.81};
  scene.connections.enabled = connections;
  const auto f = build_fin(scene);
  REQUIRE(f->continuum.rods != nullptr);
  const auto nodes = f->continuum.rods->rod_nodes(0);
  auto chord = [&] {
    const Eigen::Vector3d a = f->model->nodes().position(nodes.front()), b = f->model->nodes().position(nodes.back());
    return Eigen::Vector3d(a.z() > b.z() ? b - a : a - b);  // from the top (the joint) down to the tip
  };
  const Eigen::Vector3d rest = chord();
  sewn::physics::integrate::NewtonEuler newton;
  for (int s = 0; s < steps; ++s) (void)newton.step(f->model->system(), 0.01);
  const Eigen::Vector3d now = chord();
  return std::atan2(rest.cross(now).norm(), rest.dot(now));
}

TEST_CASE("the run's summary says whether model.connections was given when it built no energy") {
  Scene scene = sewn::app::load_scene(fin_path);
  scene.connections.detect = false;  // given, but choosing no joint
  REQUIRE(scene.connections.explicit_connections.empty());
  CHECK(sewn::app::connection_energies_text(build_fin(scene)->joints) ==
        "  energies: none (model.connections is given, but no joint found takes a rotational energy from it)\n");
  scene.connections.enabled = false;
  CHECK(sewn::app::connection_energies_text(build_fin(scene)->joints).empty());
}

TEST_CASE("the fin scene's joints get energies: one rod-shell point, four shell-solid curve edges") {
  const Scene scene = sewn::app::load_scene(fin_path);
  REQUIRE(scene.connections.enabled);
  const auto f = build_fin(scene);
  CHECK(f->joints.point_joints == 1);
  CHECK(f->joints.curve_joints == 4);
  CHECK(f->joints.curve_elements == 4);  // the fin's top line is on the block's bottom face: one hinge frame per edge
  REQUIRE(f->joints.points != nullptr);
  REQUIRE(f->joints.curves != nullptr);
  CHECK(f->continuum.rods->has_angle_dofs());
  CHECK(sewn::app::connection_energies_text(f->joints) == "  energies: 1 point, 4 curve (4 edge terms)\n");
  // the mast hangs from a node of the fin's straight bottom edge: the shell side's axis is the
  // bisector of the fan's whole 180° there, straight up into the fin (one triangle's corner
  // bisector would lean by half that corner's asymmetry), and the rod's is along the mast
  const auto frames = f->joints.points->frames(0, f->model->system().state());
  CHECK(std::abs(std::abs(frames[1].z()) - 1) < 1e-9);
  CHECK(std::abs(std::abs(frames[3].z()) - 1) < 1e-9);
  // at rest no energy and no force from the joints
  const auto s = f->model->system().state();
  CHECK(std::abs(f->joints.points->potential_energy(s)) < 1e-20);
  CHECK(std::abs(f->joints.curves->potential_energy(s)) < 1e-20);
}

TEST_CASE("the fin scene with connections holds a moment at the mast's joint; pinned, the mast swings") {
  // 40 steps of 10 ms under g = (9.81, 0, −9.81), Rayleigh α = 1/s: a pinned mast (a pendulum of
  // 0.2 m, period ~0.75 s) swings toward the pull's 45° and past it (1.18 rad measured); the
  // clamped one is a cantilever (r = 3 mm, E = 2 GPa: EI = 0.127 N·m²) whose chord turns by
  // its slope qL³/(6EI) ≈ 0.004 rad plus the joint's M/k_b ≈ 0.003 rad (k_b = EI/l̄ of a
  // 0.05 m edge), less the fin's own give (5.1e-3 rad measured).
  const double clamped = mast_tilt(true, 40), pinned = mast_tilt(false, 40);
  CAPTURE(clamped);
  CAPTURE(pinned);
  CHECK(pinned > 0.3);
  CHECK(clamped < 0.03);
}

TEST_CASE("explicit connections: only the named joints, at the mesh point named") {
  Scene scene = sewn::app::load_scene(fin_path);
  scene.connections.detect = false;
  scene.connections.explicit_connections = {{"point", {0.2, 0.1, -0.15}, std::nullopt, 5.0, std::nullopt, std::nullopt}};
  auto f = build_fin(scene);
  CHECK(f->joints.point_joints == 1);
  CHECK(f->joints.curve_joints == 0);
  CHECK(f->joints.points->connection(0).name().find("explicit[0] point connection") == 0);
  // a curve named by one of its points takes the whole curve
  scene.connections.explicit_connections = {{"curve", {0.2, 0.1, 0.0}, std::nullopt, std::nullopt, 2.0, std::nullopt}};
  f = build_fin(scene);
  CHECK(f->joints.point_joints == 0);
  CHECK(f->joints.curve_joints == 4);
}

TEST_CASE("connections: bad keys and places are refused, naming the key") {
  Scene scene = sewn::app::load_scene(fin_path);
  scene.connections.detect = false;
  // no mesh point there
  scene.connections.explicit_connections = {{"point", {5, 5, 5}, std::nullopt, std::nullopt, std::nullopt, std::nullopt}};
  CHECK(reason_of([&] { (void)build_fin(scene); }).find("model.connections.explicit[0].at: no mesh point is there: the nearest is mesh point") == 0);
  // a mesh point where no two bodies meet in a point connection (a node of the block's corner)
  scene.connections.explicit_connections = {{"point", {0, 0, 0}, std::nullopt, std::nullopt, std::nullopt, std::nullopt}};
  CHECK(reason_of([&] { (void)build_fin(scene); }).find("model.connections.explicit[0]: no two bodies meet in a point connection at mesh point") == 0);
  // the fin's top line is a curve, not points
  scene.connections.explicit_connections = {{"point", {0.2, 0.1, 0.0}, std::nullopt, std::nullopt, std::nullopt, std::nullopt}};
  CHECK(reason_of([&] { (void)build_fin(scene); }).find("model.connections.explicit[0]: no two bodies meet in a point connection") == 0);
  // rods' twist angles as DOFs need the newton integrator
  scene = sewn::app::load_scene(fin_path);
  scene.integrator = "implicit";
  CHECK(reason_of([&] { (void)build_fin(scene); }).find("model.connections: a connection with a rod side turns the rods' twist angles into degrees of freedom") == 0);

  // scene files: a point's stiffness per length, springs, a kind the schema does not know
  auto parse = [](const std::string& model) {
    const std::string text = R"({"name": "c", "materials": {"m": {"young": 1e6, "poisson": 0.3, "density": 1000}},
      "meshes": [{"type": "tet_grid", "material": "m", "cells": [1, 1, 1], "size": [1, 1, 1]}], "model": )" + model + "}";
    return reason_of([&] { (void)sewn::app::parse_scene(nlohmann::json::parse(text), "c.json"); });
  };
  CHECK(parse(R"({"type": "mixed", "connections": {"explicit": [{"kind": "point", "at": [0,0,0], "stiffness": 1}]}})") ==
        "model.connections.explicit[0].stiffness: a point connection has `twisting` and `bending`, not a stiffness per length");
  CHECK(parse(R"({"type": "mixed", "connections": {"explicit": [{"kind": "curve", "at": [0,0,0], "bending": 1}]}})") ==
        "model.connections.explicit[0].bending: a curve connection has one `stiffness` per length, not twisting and bending");
  CHECK(parse(R"({"connections": {}})").find("model.connections: connections join continuum bodies") == 0);
  CHECK(parse(R"({"type": "mixed", "connections": {"explicit": [{"kind": "surface", "at": [0,0,0]}]}})").find("model.connections.explicit[0].kind") == 0);
  CHECK(parse(R"({"type": "mixed", "connections": {"twisting": -1}})").find("model.connections.twisting") == 0);
  CHECK(parse(R"({"type": "mixed", "connections": {"detect": true, "rigid": true, "twisting": 2, "bending": 3, "curve_stiffness": 4}})") == "accepted");
}

// A block of two cubes (tetrahedra), rod A along its bottom front edge (segments on tet edges,
// a rod by its group), rod B continuing from the block's corner outward: rod–solid curve edges,
// a rod–solid point and a rod–rod point at the corner.
TEST_CASE("rods on and from a solid: curve and point connections with rod sides, forces the energy's gradient") {
  sewn::GridSpec g;
  g.spacing = {0.1, 0.1, 0.1};
  sewn::IndexedMesh m = sewn::tet_grid(2, 1, 1, sewn::TetSplit::kuhn6, g);
  m.add_cell(sewn::CellType::segment, {0, 1}, 3);
  m.add_cell(sewn::CellType::segment, {1, 2}, 3);
  const std::uint32_t r = m.num_points();
  m.points.push_back({0.3, 0.0, 0.02});
  m.points.push_back({0.4, 0.0, 0.03});
  m.add_cell(sewn::CellType::segment, {2, r}, 4);
  m.add_cell(sewn::CellType::segment, {r, r + 1}, 4);
  Scene s;
  s.file = "rods.json";
  s.model = "mixed";
  s.damping = "none";
  s.integrator = "newton";
  s.model_groups = {{3, "", "rod", {0.004, 0.004}}};
  s.connections.enabled = true;
  std::vector<sewn::physics::MaterialParams> materials{{1e7, 0.3, 1000, 0.002, 5e-5, sewn::physics::ElongatedPolicy::refuse}};
  sewn::physics::MssOptions mo;
  mo.gravity.setZero();
  mo.damping = sewn::physics::DampingModel::none;
  sewn::physics::MssModel<3> model(m, materials, std::vector<std::uint32_t>{}, mo);
  const auto groups = std::vector<int>{-1, -1, -1, -1, -1, -1, -1, -1, -1, -1, -1, -1, 0, 0, -1, -1};
  REQUIRE(groups.size() == m.num_cells());
  const auto models = sewn::app::cell_models(m, sewn::io::embedded_cells(m), s, sewn::app::MeshSource{"m", "", {}, {}}, groups);
  const auto parts = sewn::app::build_continuum(s, materials, m, models, groups, model);
  const auto joints = sewn::app::build_connections(s, m, models, materials, parts, model);
  // two rods (split by group where they meet); detection chains segments by the same rule
  REQUIRE(parts.rods != nullptr);
  CHECK(parts.rods->num_rods() == 2);
  CHECK(joints.point_joints == 2);    // rod B on the block's corner, rod A to rod B there
  CHECK(joints.curve_joints == 2);    // rod A along the two tet edges
  CHECK(joints.curve_elements == 2);  // a boundary edge of the block: its two faces as one hinge side
  REQUIRE(joints.points != nullptr);
  REQUIRE(joints.curves != nullptr);
  sewn::physics::System& sys = model.system();
  CHECK(std::abs(sys.potential_energy()) < 1e-12);
  // a deformed state, positions and twist angles: forces and torques are −∂E/∂q
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> u(-0.004, 0.004);
  for (Index i = 0; i < model.nodes().size(); ++i)
    model.nodes().set_position(i, model.nodes().position(i) + Eigen::Vector3d(u(rng), u(rng), u(rng)));
  for (double& a : sys.angles().values()) a += 50 * u(rng);
  sys.compute_forces();
  const double connected = joints.points->potential_energy(sys.state()) + joints.curves->potential_energy(sys.state());
  CHECK(connected > 0);
  double worst = 0, scale = 0;
  const double step = 1e-7;
  for (Index i = 0; i < model.nodes().size(); ++i)
    for (int a = 0; a < 3; ++a) {
      worst = std::max(worst, std::abs(sewn::app::test::energy_slope(model, i, a, step) - model.nodes().force(i)[a]));
      scale = std::max(scale, std::abs(model.nodes().force(i)[a]));
    }
  CAPTURE(worst);
  CAPTURE(scale);
  CHECK(scale > 0);
  CHECK(worst < 1e-6 * scale);
}

}  // namespace
}  // namespace test_connection_keys
